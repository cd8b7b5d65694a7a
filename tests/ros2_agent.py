"""An rclpy process the ROS 2 tests drive: one JSON command per stdin line, one JSON answer
per stdout line. Runs under the pip ROS 2's CPython 3.11 (Jazzy or Kilted), inside the test's
network namespace; an executor spins in a thread of its own while commands come.

Commands (``op``): ``sub``/``pub`` (make a subscription or publisher: ``id``, ``topic``,
``type``, ``qos``), ``publish`` (``count`` samples, or one image), ``received`` (wait for
``count`` samples, then what came), ``matched``, ``graph``, ``serve``/``call`` (std_srvs
SetBool and Trigger), ``destroy``, ``quit``. Any other message type is imported by name
(``pkg/msg/Name``); ``raw`` subscriptions keep each sample's bytes (hex), ``publish_raw`` sends
bytes as they are, and ``echo`` republishes each sample of one topic on another after rclpy's
own ``deserialize_message`` and ``serialize_message`` (whose failures it counts).
"""

import hashlib
import importlib
import json
import sys
import threading
import time

import rclpy
from rclpy.duration import Duration
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message, serialize_message

from sensor_msgs.msg import Image
from std_msgs.msg import String, UInt8MultiArray
from std_srvs.srv import SetBool, Trigger

TYPES = {"std_msgs/msg/String": String, "sensor_msgs/msg/Image": Image,
         "std_msgs/msg/UInt8MultiArray": UInt8MultiArray}
SERVICES = {"std_srvs/srv/SetBool": SetBool, "std_srvs/srv/Trigger": Trigger}


def message_type(name):
    """The rclpy class of ``pkg/msg/Name`` (the tests' few by table, any other imported)."""
    if name in TYPES:
        return TYPES[name]
    package, kind, short = name.split("/")
    cls = getattr(importlib.import_module(f"{package}.{kind}"), short)
    TYPES[name] = cls
    return cls


def qos_from(spec):
    spec = spec or {}
    qos = QoSProfile(
        reliability=ReliabilityPolicy.BEST_EFFORT if spec.get("reliability") == "best_effort"
        else ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if spec.get("durability") == "transient_local"
        else DurabilityPolicy.VOLATILE,
        history=HistoryPolicy.KEEP_ALL if spec.get("history") == "keep_all"
        else HistoryPolicy.KEEP_LAST,
        depth=spec.get("depth", 10))
    if spec.get("deadline"):
        qos.deadline = Duration(seconds=spec["deadline"])
    return qos


def summary(msg):
    if isinstance(msg, bytes):
        return msg.hex()
    if isinstance(msg, String):
        return msg.data
    data = bytes(msg.data)
    out = {"size": len(data), "md5": hashlib.md5(data).hexdigest()}
    if isinstance(msg, Image):
        out.update(width=msg.width, height=msg.height, encoding=msg.encoding,
                   frame_id=msg.header.frame_id)
    return out


class Agent:
    def __init__(self, name):
        rclpy.init()
        self.node = Node(name)
        self.executor = MultiThreadedExecutor(num_threads=4)
        self.executor.add_node(self.node)
        self.lock = threading.Condition()
        self.received = {}
        self.times = {}
        self.entities = {}
        threading.Thread(target=self.executor.spin, daemon=True).start()

    def op_sub(self, c):
        sid = c["id"]
        self.received[sid] = []
        self.times[sid] = []

        def callback(msg, sid=sid):
            item = summary(msg)
            with self.lock:
                self.received[sid].append(item)
                self.times[sid].append(time.time())
                self.lock.notify_all()
        self.entities[sid] = self.node.create_subscription(
            message_type(c["type"]), c["topic"], callback, qos_from(c.get("qos")),
            raw=bool(c.get("raw")))
        return {}

    def op_pub(self, c):
        self.entities[c["id"]] = self.node.create_publisher(message_type(c["type"]), c["topic"],
                                                            qos_from(c.get("qos")))
        return {}

    def op_publish_raw(self, c):
        pub = self.entities[c["id"]]
        for item in c["hex"]:
            pub.publish(bytes.fromhex(item))
            if c.get("rate"):
                time.sleep(1.0 / c["rate"])
        return {}

    def op_echo(self, c):
        """For each [in topic, out topic, type]: a raw subscription whose samples rclpy
        deserializes, serializes again and publishes on the out topic (reliable, depth 100)."""
        self.echoed = getattr(self, "echoed", {})
        self.echo_failures = getattr(self, "echo_failures", [])
        qos = qos_from({"depth": 100})
        for topic, out, type_name in c["topics"]:
            cls = message_type(type_name)
            pub = self.node.create_publisher(cls, out, qos)
            self.echoed[topic] = 0

            def callback(data, cls=cls, pub=pub, topic=topic, type_name=type_name):
                try:
                    msg = deserialize_message(data, cls)
                except Exception as exc:  # what the test asserts never happens
                    with self.lock:
                        self.echo_failures.append([topic, type_name, bytes(data).hex(),
                                                   f"{type(exc).__name__}: {exc}"])
                    return
                pub.publish(serialize_message(msg))
                with self.lock:
                    self.echoed[topic] += 1
            self.entities["echo " + topic] = self.node.create_subscription(
                cls, topic, callback, qos, raw=True)
            self.entities["echo out " + topic] = pub
        return {}

    def op_echo_report(self, c):
        with self.lock:
            return {"echoed": dict(self.echoed), "failures": list(self.echo_failures)}

    def op_counts(self, c):
        """Matched publishers of each subscription (or subscriptions of each publisher) in
        ``ids``, waiting until each has at least ``count``."""
        deadline = time.time() + c.get("timeout", 10)
        while True:
            counts = {}
            for eid in c["ids"]:
                entity = self.entities[eid]
                counts[eid] = (entity.get_subscription_count()
                               if hasattr(entity, "get_subscription_count")
                               else entity.get_publisher_count())
            if all(v >= c.get("count", 1) for v in counts.values()) or time.time() > deadline:
                return {"counts": counts}
            time.sleep(0.02)

    def op_matched(self, c):
        entity = self.entities[c["id"]]
        deadline = time.time() + c.get("timeout", 10)
        count = c.get("count", 1)
        get = (entity.get_subscription_count if hasattr(entity, "get_subscription_count")
               else entity.get_publisher_count)
        while get() < count and time.time() < deadline:
            time.sleep(0.01)
        return {"count": get()}

    def op_publish(self, c):
        pub = self.entities[c["id"]]
        rate = c.get("rate")
        if c.get("image"):
            w, h = c.get("width", 1920), c.get("height", 1080)
            out = []
            for i in range(c.get("count", 1)):
                data = bytes([(i * 7 + 3) % 256]) * (w * h * 3)
                msg = Image(height=h, width=w, encoding="rgb8", step=w * 3, data=data)
                msg.header.frame_id = "camera"
                pub.publish(msg)
                out.append(hashlib.md5(data).hexdigest())
                if rate:
                    time.sleep(1.0 / rate)
            return {"md5": out}
        for i in range(c.get("count", 1)):
            pub.publish(String(data=f"{c.get('prefix', 'hello')} {i}"))
            if rate:
                time.sleep(1.0 / rate)
        return {}

    def op_received(self, c):
        sid = c["id"]
        deadline = time.time() + c.get("timeout", 10)
        with self.lock:
            while len(self.received[sid]) < c.get("count", 1) and time.time() < deadline:
                self.lock.wait(0.05)
            items = list(self.received[sid])
            times = list(self.times[sid])
        return {"items": items if c.get("items", True) else [], "count": len(items),
                "times": times if c.get("with_times") else []}

    def op_graph(self, c):
        deadline = time.time() + c.get("timeout", 0)
        while True:
            nodes = self.node.get_node_names_and_namespaces()
            if not c.get("want_node") or any(n == c["want_node"] for n, _ in nodes) \
                    or time.time() >= deadline:
                break
            time.sleep(0.01)
        out = {"nodes": nodes, "topics": self.node.get_topic_names_and_types(),
               "services": self.node.get_service_names_and_types()}
        if c.get("topic"):
            out["publishers"] = [
                {"node": i.node_name, "namespace": i.node_namespace, "type": i.topic_type,
                 "hash": str(i.topic_type_hash), "reliability": i.qos_profile.reliability.name,
                 "durability": i.qos_profile.durability.name}
                for i in self.node.get_publishers_info_by_topic(c["topic"])]
            out["subscriptions"] = [
                {"node": i.node_name, "namespace": i.node_namespace, "type": i.topic_type,
                 "hash": str(i.topic_type_hash), "reliability": i.qos_profile.reliability.name,
                 "durability": i.qos_profile.durability.name}
                for i in self.node.get_subscriptions_info_by_topic(c["topic"])]
        return out

    def op_serve(self, c):
        srv_type = SERVICES[c["type"]]

        def handle(request, response):
            if srv_type is SetBool:
                response.success = request.data
                response.message = f"rclpy set {request.data}"
            else:
                response.success = True
                response.message = "rclpy triggered"
            return response
        self.entities[c["id"]] = self.node.create_service(srv_type, c["name"], handle)
        return {}

    def op_call(self, c):
        srv_type = SERVICES[c["type"]]
        client = self.entities.get(c["id"])
        if client is None:
            client = self.entities[c["id"]] = self.node.create_client(srv_type, c["name"])
        t0 = time.time()
        ready = client.wait_for_service(timeout_sec=c.get("timeout", 10))
        if not ready:
            return {"ready": False}
        results = []
        for _ in range(c.get("count", 1)):
            request = (SetBool.Request(data=bool(c.get("data", True)))
                       if srv_type is SetBool else Trigger.Request())
            future = client.call_async(request)
            done = threading.Event()
            future.add_done_callback(lambda f, done=done: done.set())
            done.wait(c.get("timeout", 10))
            result = future.result() if future.done() else None
            results.append(None if result is None else
                           {"success": result.success, "message": result.message})
        return {"ready": True, "wait": time.time() - t0, "results": results}

    def op_destroy(self, c):
        entity = self.entities.pop(c["id"])
        if hasattr(entity, "get_subscription_count"):
            self.node.destroy_publisher(entity)
        elif hasattr(entity, "wait_for_service"):
            self.node.destroy_client(entity)
        elif hasattr(entity, "service_name") or hasattr(entity, "srv_type"):
            self.node.destroy_service(entity)
        else:
            self.node.destroy_subscription(entity)
        return {}


def main():
    agent = Agent(sys.argv[1] if len(sys.argv) > 1 else "rclpy_agent")
    print(json.dumps({"ready": True, "pid": __import__("os").getpid()}), flush=True)
    for line in sys.stdin:
        command = json.loads(line)
        if command["op"] == "quit":
            break
        try:
            answer = getattr(agent, "op_" + command["op"])(command)
        except Exception as exc:  # the test reads the error
            answer = {"error": f"{type(exc).__name__}: {exc}"}
        print(json.dumps(answer), flush=True)
    agent.executor.shutdown(timeout_sec=1)
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
