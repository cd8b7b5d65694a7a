"""A Cyclone DDS process (cyclonedds-python) for the bridge tests: it builds IDL types at run
time from a description the test sends, reads one topic and writes every sample it reads to
another (ROS 2's conventions: ``rt/`` topics, ``pkg::msg::dds_::Name_`` types, final structs,
plain CDR), and reports what it read. One JSON command per stdin line, one answer per line.

``types``: a list of structs in dependency order, each ``{"name": DDS name, "fields":
[[name, spec]]}`` where a spec is ``{"base": primitive or DDS struct name, "kind": "scalar" |
"array" | "bounded" | "sequence", "size": N}``; ``echo``: ``type``, ``topic``, ``out``;
``received``: what the echo read, as plain values.
"""

import dataclasses
import json
import os
import sys
import threading
import time
import types as pytypes

import cyclonedds.idl.annotations as annotate
from cyclonedds.core import Listener, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t
from cyclonedds.pub import DataWriter
from cyclonedds.qos import Policy
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

PRIMITIVES = {
    "bool": bool, "byte": t.uint8, "octet": t.uint8, "char": t.uint8, "int8": t.int8,
    "uint8": t.uint8, "int16": t.int16, "uint16": t.uint16, "int32": t.int32,
    "uint32": t.uint32, "int64": t.int64, "uint64": t.uint64, "float32": t.float32,
    "float64": t.float64, "string": str,
}


def plain(value):
    if dataclasses.is_dataclass(value):
        return {f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, bytes):
        return list(value)
    return value


class Agent:
    def __init__(self):
        self.dp = DomainParticipant(0)
        self.structs = {}
        self.lock = threading.Condition()
        self.received = []
        self.entities = []

    def _annotation(self, spec):
        base = spec["base"]
        element = PRIMITIVES.get(base) or self.structs[base]
        kind = spec["kind"]
        if kind == "array":
            return t.array[element, spec["size"]]
        if kind == "bounded":
            return t.sequence[element, spec["size"]]
        if kind == "sequence":
            return t.sequence[element]
        return element

    def op_types(self, c):
        for struct in c["types"]:
            name = struct["name"]
            annotations = {fname: self._annotation(spec) for fname, spec in struct["fields"]}
            cls = pytypes.new_class(
                name.split("::")[-1], (IdlStruct,), {"typename": name},
                lambda ns, a=annotations: ns.update({"__annotations__": a}))
            self.structs[name] = annotate.final(dataclasses.dataclass(cls))
        return {"made": sorted(self.structs)}

    def op_echo(self, c):
        cls = self.structs[c["type"]]
        qos = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)),
                  Policy.Durability.Volatile, Policy.History.KeepLast(100),
                  Policy.DataRepresentation(use_cdrv0_representation=True))
        writer = DataWriter(self.dp, Topic(self.dp, "rt/" + c["out"], cls), qos=qos)

        def on_data(reader):
            for sample in reader.take(N=100):
                with self.lock:
                    self.received.append(plain(sample))
                    self.lock.notify_all()
                writer.write(sample)
        reader = DataReader(self.dp, Topic(self.dp, "rt/" + c["topic"], cls), qos=qos,
                            listener=Listener(on_data_available=on_data))
        self.entities += [reader, writer]
        return {}

    def op_received(self, c):
        deadline = time.time() + c.get("timeout", 10)
        with self.lock:
            while len(self.received) < c.get("count", 1) and time.time() < deadline:
                self.lock.wait(0.05)
            return {"items": list(self.received), "count": len(self.received)}


def main():
    agent = Agent()
    print(json.dumps({"ready": True, "pid": os.getpid()}), flush=True)
    for line in sys.stdin:
        command = json.loads(line)
        if command["op"] == "quit":
            break
        try:
            answer = getattr(agent, "op_" + command["op"])(command)
        except Exception as exc:  # the test reads the error
            answer = {"error": f"{type(exc).__name__}: {exc}"}
        print(json.dumps(answer), flush=True)


if __name__ == "__main__":
    main()
