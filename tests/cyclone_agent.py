"""A Cyclone DDS process (cyclonedds-python) the ROS 2 tests drive, as tests/ros2_agent.py:
one JSON command per stdin line, one JSON answer per line. It speaks ROS 2's DDS conventions
as rmw_cyclonedds does (``rt/`` topics, ``pkg::msg::dds_::Name_`` types, services with the
in-band ``cdds_request_header_t {uint64 guid; int64 seq}`` first in each request and reply, and
``clientid=``/``serviceid=`` in USER_DATA), since rmw_cyclonedds is not on PyPI.
"""

import hashlib
import json
import os
import sys
import threading
import time
from dataclasses import dataclass

import cyclonedds.idl.annotations as annotate
from cyclonedds.core import Listener, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int64, sequence, uint8, uint32, uint64
from cyclonedds.pub import DataWriter
from cyclonedds.qos import Policy
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


@dataclass
@annotate.final
class String_(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str


@dataclass
@annotate.final
class MultiArrayDimension_(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayDimension_"):
    label: str
    size: uint32
    stride: uint32


@dataclass
@annotate.final
class MultiArrayLayout_(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayLayout_"):
    dim: sequence[MultiArrayDimension_]
    data_offset: uint32


@dataclass
@annotate.final
class UInt8MultiArray_(IdlStruct, typename="std_msgs::msg::dds_::UInt8MultiArray_"):
    layout: MultiArrayLayout_
    data: sequence[uint8]


# rmw_cyclonedds's wire form of a service: the request header, then the request's fields
@dataclass
@annotate.final
class SetBool_Request_(IdlStruct, typename="std_srvs::srv::dds_::SetBool_Request_"):
    guid: uint64
    seq: int64
    data: bool


@dataclass
@annotate.final
class SetBool_Response_(IdlStruct, typename="std_srvs::srv::dds_::SetBool_Response_"):
    guid: uint64
    seq: int64
    success: bool
    message: str


TYPES = {"std_msgs/msg/String": String_, "std_msgs/msg/UInt8MultiArray": UInt8MultiArray_}


def qos_from(spec, user_data=b""):
    spec = spec or {}
    policies = [
        Policy.Reliability.BestEffort if spec.get("reliability") == "best_effort"
        else Policy.Reliability.Reliable(duration(milliseconds=100)),
        Policy.Durability.TransientLocal if spec.get("durability") == "transient_local"
        else Policy.Durability.Volatile,
        Policy.History.KeepLast(spec.get("depth", 10)),
        Policy.DataRepresentation(use_cdrv0_representation=True),
    ]
    if user_data:
        policies.append(Policy.Userdata(user_data))
    return Qos(*policies)


def summary(msg):
    if isinstance(msg, String_):
        return msg.data
    data = bytes(msg.data)
    return {"size": len(data), "md5": hashlib.md5(data).hexdigest()}


class Agent:
    def __init__(self):
        self.dp = DomainParticipant(0)
        self.lock = threading.Condition()
        self.received = {}
        self.entities = {}
        self.topics = {}

    def topic(self, name, cls):
        key = (name, cls)
        if key not in self.topics:
            self.topics[key] = Topic(self.dp, name, cls)
        return self.topics[key]

    def op_sub(self, c):
        sid = c["id"]
        self.received[sid] = []

        def on_data(reader, sid=sid):
            for msg in reader.take(N=100):
                with self.lock:
                    self.received[sid].append(summary(msg))
                    self.lock.notify_all()
        topic = self.topic("rt/" + c["topic"], TYPES[c["type"]])
        self.entities[sid] = DataReader(self.dp, topic, qos=qos_from(c.get("qos")),
                                        listener=Listener(on_data_available=on_data))
        return {}

    def op_pub(self, c):
        topic = self.topic("rt/" + c["topic"], TYPES[c["type"]])
        self.entities[c["id"]] = DataWriter(self.dp, topic, qos=qos_from(c.get("qos")))
        return {}

    def op_matched(self, c):
        entity = self.entities[c["id"]]
        deadline = time.time() + c.get("timeout", 10)
        get = (entity.get_matched_subscriptions if isinstance(entity, DataWriter)
               else entity.get_matched_publications)
        while len(get()) < c.get("count", 1) and time.time() < deadline:
            time.sleep(0.01)
        return {"count": len(get())}

    def op_publish(self, c):
        writer = self.entities[c["id"]]
        out = []
        for i in range(c.get("count", 1)):
            if c.get("size"):
                data = bytes([(i * 13 + 1) % 256]) * c["size"]
                writer.write(UInt8MultiArray_(MultiArrayLayout_([], 0), list(data)))
                out.append(hashlib.md5(data).hexdigest())
            else:
                writer.write(String_(f"{c.get('prefix', 'hello')} {i}"))
            if c.get("rate"):
                time.sleep(1.0 / c["rate"])
        return {"md5": out}

    def op_received(self, c):
        sid = c["id"]
        deadline = time.time() + c.get("timeout", 10)
        with self.lock:
            while len(self.received[sid]) < c.get("count", 1) and time.time() < deadline:
                self.lock.wait(0.05)
                # cyclonedds-python's listener does not always fire for a sample that came
                # while the reader was being made (transient-local history): read it too
                for msg in self.entities[sid].take(N=100):
                    self.received[sid].append(summary(msg))
            return {"items": list(self.received[sid]), "count": len(self.received[sid])}

    def op_serve(self, c):
        """A SetBool server as rmw_cyclonedds writes one."""
        user_data = f"serviceid={os.urandom(8).hex()};".encode()
        req = self.topic(f"rq/{c['name']}Request", SetBool_Request_)
        rep = self.topic(f"rr/{c['name']}Reply", SetBool_Response_)
        writer = DataWriter(self.dp, rep, qos=qos_from({}, user_data))

        def on_request(reader):
            for r in reader.take(N=100):
                writer.write(SetBool_Response_(r.guid, r.seq, r.data, f"cyclone set {r.data}"))
        reader = DataReader(self.dp, req, qos=qos_from({}, user_data),
                            listener=Listener(on_data_available=on_request))
        self.entities[c["id"]] = (reader, writer)
        return {}

    def op_call(self, c):
        """SetBool calls as rmw_cyclonedds's client makes them."""
        guid = int.from_bytes(os.urandom(8), "little") >> 1
        user_data = f"clientid={guid:x};".encode()
        req = self.topic(f"rq/{c['name']}Request", SetBool_Request_)
        rep = self.topic(f"rr/{c['name']}Reply", SetBool_Response_)
        writer = DataWriter(self.dp, req, qos=qos_from({}, user_data))
        reader = DataReader(self.dp, rep, qos=qos_from({}, user_data))
        deadline = time.time() + c.get("timeout", 10)
        while (not writer.get_matched_subscriptions() or not reader.get_matched_publications()) \
                and time.time() < deadline:
            time.sleep(0.01)
        if not writer.get_matched_subscriptions() or not reader.get_matched_publications():
            return {"ready": False}
        time.sleep(0.2)  # the server's side of the match (rmw_cyclonedds waits for it too)
        results = []
        for seq in range(1, c.get("count", 1) + 1):
            writer.write(SetBool_Request_(guid, seq, bool(c.get("data", True))))
            answer = None
            while answer is None and time.time() < deadline:
                for r in reader.take(N=10):
                    if r.guid == guid and r.seq == seq:
                        answer = {"success": r.success, "message": r.message}
                time.sleep(0.005)
            results.append(answer)
        return {"ready": True, "results": results}


def main():
    agent = Agent()
    print(json.dumps({"ready": True, "pid": os.getpid()}), flush=True)
    for line in sys.stdin:
        command = json.loads(line)
        if command["op"] == "quit":
            break
        try:
            answer = getattr(agent, "op_" + command["op"])(command)
        except Exception as exc:
            answer = {"error": f"{type(exc).__name__}: {exc}"}
        print(json.dumps(answer), flush=True)


if __name__ == "__main__":
    main()
