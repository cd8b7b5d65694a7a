"""A minros ROS 1 node the bridge tests drive (as tests/ros2_agent.py drives rclpy): one JSON
command per stdin line, one JSON answer per stdout line, inside the test's network namespace.

It carries serialized bytes (hex in JSON) under any type, so the test builds and checks the
messages itself: ``pub`` (topic, type, md5, definition, latch), ``publish`` (hex payloads),
``sub`` (topic, type; md5sum ``*``), ``received`` (what came, with each connection's callerid),
``clock`` (simulated time: publish /clock steps, each waiting for one message on a
subscription, so a rospy.Rate loop runs in lock step), ``call`` (a raw service call),
``quit``.
"""

import json
import sys
import threading
import time

import minros

_classes = {}


def raw_class(type_name, md5sum="*", definition=""):
    key = (type_name, md5sum, definition)
    if key not in _classes:
        _classes[key] = type("Raw", (minros.AnyMsg,), {
            "__slots__": (), "_type": type_name, "_md5sum": md5sum, "_full_text": definition,
            "_has_header": False})
    return _classes[key]


class Agent:
    def __init__(self, name):
        minros.init_node(name, disable_signals=True)
        self.lock = threading.Condition()
        self.received = {}
        self.entities = {}

    def op_pub(self, c):
        cls = raw_class(c["type"], c.get("md5", "*"), c.get("definition", ""))
        self.entities[c["id"]] = (minros.Publisher(c["topic"], cls, latch=c.get("latch", False),
                                                   queue_size=c.get("queue_size", 1000)), cls)
        return {}

    def op_publish(self, c):
        pub, cls = self.entities[c["id"]]
        deadline = time.time() + c.get("timeout", 10)
        while pub.get_num_connections() < c.get("wait_for", 0) and time.time() < deadline:
            time.sleep(0.005)
        rate = c.get("rate")
        for item in c["hex"]:
            pub.publish(cls(bytes.fromhex(item)))
            if rate:
                time.sleep(1.0 / rate)
        return {"connections": pub.get_num_connections()}

    def op_publish_images(self, c):
        """``count`` sensor_msgs/Image frames (rgb8) of which each byte is the frame's number
        times 7 plus 3; the md5 sums of their data."""
        import hashlib

        from sensor_msgs.msg import Image

        if c["id"] not in self.entities:
            self.entities[c["id"]] = (minros.Publisher(c["topic"], Image, queue_size=10), Image)
        pub, _cls = self.entities[c["id"]]
        w, h = c.get("width", 1920), c.get("height", 1080)
        out = []
        for i in range(c.get("count", 1)):
            data = bytes([(i * 7 + 3) % 256]) * (w * h * 3)
            pub.publish(Image(height=h, width=w, encoding="rgb8", step=w * 3, data=data))
            out.append(hashlib.md5(data).hexdigest())
            if c.get("rate"):
                time.sleep(1.0 / c["rate"])
        return {"md5": out}

    def op_image_sub(self, c):
        """A subscription keeping (width, height, encoding, seq, md5 of the data) per image."""
        import hashlib

        from sensor_msgs.msg import Image

        sid = c["id"]
        self.received[sid] = []

        def callback(msg, sid=sid):
            with self.lock:
                self.received[sid].append(
                    [msg.width, msg.height, msg.encoding, msg.header.seq,
                     hashlib.md5(bytes(msg.data)).hexdigest()])
                self.lock.notify_all()
        self.entities[sid] = minros.Subscriber(c["topic"], Image, callback, queue_size=10)
        return {}

    def op_images(self, c):
        sid = c["id"]
        deadline = time.time() + c.get("timeout", 10)
        with self.lock:
            while len(self.received[sid]) < c.get("count", 1) and time.time() < deadline:
                self.lock.wait(0.05)
            return {"items": list(self.received[sid])}

    def op_connections(self, c):
        pub, _cls = self.entities[c["id"]]
        deadline = time.time() + c.get("timeout", 10)
        while pub.get_num_connections() < c.get("count", 1) and time.time() < deadline:
            time.sleep(0.005)
        return {"count": pub.get_num_connections()}

    def op_sub(self, c):
        sid = c["id"]
        self.received[sid] = []

        def callback(msg, sid=sid):
            header = msg._connection_header
            with self.lock:
                self.received[sid].append((bytes(msg._buff).hex(), header.get("callerid", ""),
                                           header.get("latching", "0")))
                self.lock.notify_all()
        cls = raw_class(c["type"], c.get("md5", "*"), c.get("definition", ""))
        self.entities[sid] = minros.Subscriber(c["topic"], cls, callback, queue_size=10000)
        return {}

    def op_received(self, c):
        sid = c["id"]
        deadline = time.time() + c.get("timeout", 10)
        with self.lock:
            while len(self.received[sid]) < c.get("count", 1) and time.time() < deadline:
                self.lock.wait(0.05)
            items = list(self.received[sid])
        return {"items": [i[0] for i in items], "callers": sorted({i[1] for i in items}),
                "latching": sorted({i[2] for i in items}), "count": len(items)}

    def op_clock(self, c):
        """Publish /clock from ``start`` in ``step`` seconds; after each step wait until
        subscription ``id`` has one more message (``timeout`` each)."""
        from rosgraph_msgs.msg import Clock

        if "clock" not in self.entities:
            self.entities["clock"] = minros.Publisher("/clock", Clock, queue_size=10)
        pub = self.entities["clock"]
        deadline = time.time() + 10
        while pub.get_num_connections() < c.get("wait_for", 1) and time.time() < deadline:
            time.sleep(0.005)
        sid = c["id"]
        t = int(round(c["start"] * 1e9))  # whole nanoseconds: a Rate's next time is exact
        step = int(round(c["step"] * 1e9))
        missed = 0
        for _ in range(c["count"]):
            with self.lock:
                before = len(self.received[sid])
            t += step
            if c.get("rate"):
                time.sleep(1.0 / c["rate"])
            pub.publish(Clock(clock=minros.Time(t // 10**9, t % 10**9)))
            with self.lock:
                if not self.lock.wait_for(lambda n=before: len(self.received[sid]) > n,
                                          c.get("timeout", 2)):
                    missed += 1
        return {"time": t / 1e9, "missed": missed}

    def op_call(self, c):
        from minros.ros2.bridge.raw import raw_service_class

        cls = raw_service_class(c["type"], c["md5"])
        proxy = minros.ServiceProxy(c["service"], cls)
        try:
            proxy.wait_for_service(c.get("timeout", 10))
            reply = proxy.call(cls._request_class(bytes.fromhex(c["hex"])))
            return {"hex": bytes(reply._buff).hex()}
        except Exception as exc:  # the test reads the error
            return {"failed": f"{type(exc).__name__}: {exc}"}
        finally:
            proxy.close()

    def op_many(self, c):
        """Several commands in one: ``commands`` is a list of them; the answers' list."""
        return {"answers": [getattr(self, "op_" + sub.pop("op"))(sub) for sub in c["commands"]]}

    def op_pub_connections(self, c):
        """Wait until each publisher in ``ids`` has ``count`` subscribers connected."""
        deadline = time.time() + c.get("timeout", 10)
        while True:
            counts = {i: self.entities[i][0].get_num_connections() for i in c["ids"]}
            if all(v >= c.get("count", 1) for v in counts.values()) or time.time() > deadline:
                return {"counts": counts}
            time.sleep(0.01)

    def op_sub_connections(self, c):
        """Wait until each subscription in ``ids`` is connected to ``count`` publishers."""
        deadline = time.time() + c.get("timeout", 10)
        while True:
            counts = {i: self.entities[i].get_num_connections() for i in c["ids"]}
            if all(v >= c.get("count", 1) for v in counts.values()) or time.time() > deadline:
                return {"counts": counts}
            time.sleep(0.01)

    def op_param(self, c):
        if c.get("delete"):
            minros.delete_param(c["name"])
        else:
            minros.set_param(c["name"], c["value"])
        return {}

    def op_unregister(self, c):
        entity = self.entities.pop(c["id"])
        (entity[0] if isinstance(entity, tuple) else entity).unregister()
        return {}


def main():
    agent = Agent(sys.argv[1] if len(sys.argv) > 1 else "ros1_agent")
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
    minros.signal_shutdown("done")


if __name__ == "__main__":
    main()
