#!/usr/bin/env python3
"""Capture the RTPS byte vectors minros's wire tests check against, from real peers.

For each source (Fast DDS of ROS 2 Jazzy and Kilted, from the pip rclpy; Cyclone DDS 11.0.1,
from cyclonedds-python) a short scenario runs in a network namespace of its own with only
loopback, under tshark: discovery, a String topic, a SetBool call, a fragmented sample, and a
fragment minros withholds on purpose so that the Fast DDS reader asks for it (NACK_FRAG). The
first datagram of each kind is kept with what Wireshark's RTPS dissector says about it (an
oracle independent of minros), in tests/unit/data/rtps_vectors.json.

    sudo .venv/bin/python scripts/rtps_vectors.py          # rewrite the vectors
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, List

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "tests"))

from ros2_support import (  # noqa: E402
    CYCLONE_AGENT,
    CYCLONE_URI,
    Agent,
    Netns,
    context,
    cyclone_python,
    ros2_env,
    ros2_python,
)

OUT = REPO / "tests" / "unit" / "data" / "rtps_vectors.json"

SCENARIO = r'''
import sys, time, rclpy
from rclpy.node import Node
from std_msgs.msg import String, UInt8MultiArray
from std_srvs.srv import SetBool
role = sys.argv[1]
rclpy.init()
n = Node(role)
if role == "pub":
    p = n.create_publisher(String, "chatter", 10)
    b = n.create_publisher(UInt8MultiArray, "big", 10)
    def handle(req, resp):
        resp.success = req.data
        resp.message = "on"
        return resp
    srv = n.create_service(SetBool, "set", handle)
    end = time.time() + 4
    i = 0
    while time.time() < end:
        p.publish(String(data="hello %d" % i)); i += 1
        if i % 10 == 0:
            b.publish(UInt8MultiArray(data=bytes(range(256)) * 1000))
        rclpy.spin_once(n, timeout_sec=0.1)
else:
    s = n.create_subscription(String, "chatter", lambda m: None, 10)
    s2 = n.create_subscription(UInt8MultiArray, "big", lambda m: None, 10)
    s3 = n.create_subscription(UInt8MultiArray, "withheld", lambda m: None, 10)
    c = n.create_client(SetBool, "set")
    c.wait_for_service(3)
    f = c.call_async(SetBool.Request(data=True))
    rclpy.spin_until_future_complete(n, f, timeout_sec=3)
    end = time.time() + 3
    while time.time() < end:
        rclpy.spin_once(n, timeout_sec=0.1)
'''

FIELDS = ["frame.number", "udp.srcport", "udp.dstport", "udp.payload", "rtps.vendorId",
          "rtps.guidPrefix.src", "rtps.sm.id", "rtps.sm.wrEntityId", "rtps.sm.rdEntityId",
          "rtps.sm.seqNumber", "rtps.param.topicName", "rtps.param.typeName",
          "rtps.locator.port", "rtps.data_frag.number", "rtps.data_frag.sample_size",
          "rtps.data_frag.size", "rtps.data_frag.num_fragments", "rtps.bitmap.num_bits",
          "rtps.fragment_number.base32", "rtps.acknack.count", "rtps.nack_frag.count",
          "rtps.participant_builtin_endpoints", "rtps.param.builtin_endpoint_set",
          "rtps.reliability_kind", "rtps.durability", "rtps.param.userData"]


def capture(name: str, run: Callable[[Netns, Path], None]) -> list:
    """Run ``run(ns, tmp)`` under tshark in a fresh namespace; the frames as field dicts."""
    ns = Netns()
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        pcap = tmp / f"{name}.pcapng"
        dumpcap = subprocess.Popen(ns.argv(["dumpcap", "-q", "-i", "lo", "-w", str(pcap)]),
                                   stderr=subprocess.DEVNULL)
        try:
            time.sleep(1.5)
            run(ns, tmp)
            time.sleep(0.5)
        finally:
            dumpcap.terminate()
            dumpcap.wait(10)
            ns.delete()
        out = subprocess.run(["tshark", "-r", str(pcap), "-Y", "rtps", "-T", "json",
                              *sum((["-e", f] for f in FIELDS), [])],
                             capture_output=True, text=True, check=True).stdout
    return [frame["_source"]["layers"] for frame in json.loads(out)]


def run_fastdds(distro: str) -> Callable[[Netns, Path], None]:
    def run(ns: Netns, tmp: Path) -> None:
        script = tmp / "scenario.py"
        script.write_text(SCENARIO)
        env = ros2_env(tmp, {"FASTDDS_BUILTIN_TRANSPORTS": "UDPv4"})
        py = str(ros2_python(distro))
        pub = subprocess.Popen(ns.argv([py, str(script), "pub"]), env=env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(0.3)
        sub = subprocess.Popen(ns.argv([py, str(script), "sub"]), env=env,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(1.5)
        withhold_a_fragment(ns)
        sub.wait(30)
        pub.wait(30)
    return run


def withhold_a_fragment(ns: Netns) -> None:
    """A minros publisher on "withheld" that does not send fragment 2 of its first sample:
    the Fast DDS reader asks for it with a NACK_FRAG, and gets it."""
    from minros.ros2.rtps import messages as m
    from minros.ros2.rtps import participant as part

    ctx = context(ns)
    original = part.Participant._send
    dropped = []

    def send(self: Any, datagrams: List[Any]) -> None:
        kept = []
        for dg in datagrams:
            heads = [bytes(b[:36]) for b in dg.buffers[1:] if len(b) >= 36 and b[0] == m.DATA_FRAG]
            if not dropped and heads and int.from_bytes(heads[0][24:28], "little") == 2:
                dropped.append(dg)
                continue
            kept.append(dg)
        original(self, kept)
    part.Participant._send = send
    try:
        node = ctx.create_node("withholder")
        pub = node.create_publisher("withheld", "std_msgs/msg/UInt8MultiArray")
        pub.wait_for_subscriptions(1, 5)
        data = bytes(200_000)
        pub.publish(b"\x00\x01\x00\x00" + (0).to_bytes(4, "little") * 2
                    + len(data).to_bytes(4, "little") + data)
        pub.wait_for_acknowledgments(3)
    finally:
        part.Participant._send = original
        ctx.shutdown()


def run_cyclone(ns: Netns, tmp: Path) -> None:
    agent = Agent(ns, cyclone_python(), CYCLONE_AGENT, "cyclone", tmp,
                  env={"CYCLONEDDS_URI": CYCLONE_URI})
    ctx = context(ns)
    try:
        node = ctx.create_node("listener")
        node.create_subscription("chatter", "std_msgs/msg/String", lambda p, i: None)
        node.create_subscription("big", "std_msgs/msg/UInt8MultiArray", lambda p, i: None)
        # a SetBool server the Cyclone client calls in rmw_cyclonedds's in-band form
        node.create_service("set", "std_srvs/srv/SetBool",
                            lambda req: b"\x00\x01\x00\x00\x01\x00\x00\x00\x03\x00\x00\x00on\x00")
        agent("pub", id="talker", topic="chatter", type="std_msgs/msg/String")
        agent("pub", id="big", topic="big", type="std_msgs/msg/UInt8MultiArray")
        agent("matched", id="talker")
        agent("matched", id="big")
        agent("publish", id="talker", count=5)
        agent("publish", id="big", count=1, size=20_000)
        agent("call", name="set", data=True)
        time.sleep(0.5)
    finally:
        ctx.shutdown()
        agent.close()


def first(frames: list, predicate: Callable[[dict], bool]) -> dict:
    for f in frames:
        if predicate(f):
            return f
    raise SystemExit("no frame matched")


def ids(f: dict) -> list:
    return f.get("rtps.sm.id", [])


def user(f: dict) -> bool:
    """Every submessage is of a user-defined writer without a key (kind 0x03)."""
    writers = f.get("rtps.sm.wrEntityId", [])
    return bool(writers) and all(w.endswith("03") for w in writers)


def topics(f: dict) -> list:
    return f.get("rtps.param.topicName", [])


def kinds(frames: list, source: str, vendor: str) -> list:
    """The datagrams kept: the first of each kind sent by ``vendor`` ("0x010f"...)."""
    theirs = [f for f in frames if vendor in f.get("rtps.vendorId", [""])[0]]
    picks = {
        "spdp": lambda f: "0x000100c2" in f.get("rtps.sm.wrEntityId", []),
        "sedp_publication": lambda f: "0x000003c2" in f.get("rtps.sm.wrEntityId", [])
        and "0x15" in ids(f) and "rt/chatter" in f.get("rtps.param.topicName", []),
        "sedp_subscription": lambda f: "0x000004c2" in f.get("rtps.sm.wrEntityId", [])
        and "0x15" in ids(f),
        "user_data": lambda f: "0x15" in ids(f) and "rt/chatter" in topics(f) and user(f),
        "request": lambda f: "0x15" in ids(f) and "rq/setRequest" in topics(f) and user(f),
        "reply": lambda f: "0x15" in ids(f) and "rr/setReply" in topics(f) and user(f),
        "discovery_info": lambda f: "0x15" in ids(f) and "ros_discovery_info" in topics(f)
        and user(f),
        "heartbeat": lambda f: "0x07" in ids(f),
        "acknack": lambda f: "0x06" in ids(f) and any(
            r in ("0x000003c7", "0x000004c7") for r in f.get("rtps.sm.rdEntityId", [])),
        "data_frag": lambda f: "0x16" in ids(f),
        "nack_frag": lambda f: "0x12" in ids(f),
        "gap": lambda f: "0x08" in ids(f),
    }
    out = []
    for name, pick in picks.items():
        try:
            f = first(theirs, pick)
        except SystemExit:
            continue
        raw = f["udp.payload"][0].replace(":", "")
        # a fragment's bytes are not what the tests read: of a big one keep 2 KB and its length
        out.append({"source": source, "kind": name, "frame": int(f["frame.number"][0]),
                    "length": len(raw) // 2,
                    "hex": raw[:4096] if len(raw) > 32768 else raw,
                    "tshark": {k: v for k, v in f.items() if k != "udp.payload"}})
    return out


def main() -> None:
    if os.geteuid() != 0:
        raise SystemExit("network namespaces need root")
    vectors = []
    for distro in ("jazzy", "kilted"):
        frames = capture(distro, run_fastdds(distro))
        vectors += kinds(frames, f"Fast DDS ({distro}, rclpy)", "0x010f")
        if distro == "jazzy":
            vectors += [v for v in kinds(frames, "minros", "0x016d")
                        if v["kind"] in ("spdp", "data_frag", "heartbeat")]
    frames = capture("cyclone", run_cyclone)
    vectors += kinds(frames, "Cyclone DDS 11.0.1 (cyclonedds-python)", "0x0110")
    vectors += [v for v in kinds(frames, "minros (to Cyclone)", "0x016d") if v["kind"] == "reply"]
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(vectors, indent=1) + "\n")
    for v in vectors:
        print(f"{v['source']:40} {v['kind']:18} {len(v['hex']) // 2:6} bytes")


if __name__ == "__main__":
    main()
