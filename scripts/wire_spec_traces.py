#!/usr/bin/env python3
"""Regenerate, or check, the trace excerpts of docs/wire.md from one real run.

    .venv/bin/python scripts/wire_spec_traces.py --write    rewrite the excerpts in the doc
    .venv/bin/python scripts/wire_spec_traces.py --check    exit 1 when the doc disagrees

docs/wire.md states the ROS 1 wire protocol (TCPROS framing, the connection header fields of
each side, requestTopic, the service ok byte, the XML-RPC calls) and links every claim to an
excerpt between ``<!-- wire: NAME -->`` and ``<!-- /wire -->``. This script makes them all
from one run: a traced ``minros core``; a minros node, Debian's rospy and a roscpp node
compiled here, each publishing, subscribing, serving and calling a service of the others (the
minros side is traced, so it records what the real ROS sent it as well as what it sent); a
subscriber built from a stale definition that all three refuse; and a traced process that
makes every Master and Slave API call once. ``--check`` compares with this run, ignoring
what changes between runs (ports, pids, times). tests/interop/test_wire_spec_doc.py runs it.
"""

from __future__ import annotations

import argparse
import difflib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

sys.path.insert(0, str(Path(__file__).resolve().parent))

from internals_traces import PYTHON, REPO, Session, normalize, sections_only  # noqa: E402

DOC = REPO / "docs" / "wire.md"
BLOCK = re.compile(r"(<!-- wire: (?P<name>[\w-]+) -->\n)(?P<body>.*?)(<!-- /wire -->)", re.S)
REFERENCE_PYTHON = "/usr/bin/python3"

#: minros: publishes /chatter, subscribes the others' topics, serves /minros_set, and calls
#: /rospy_set and /cpp_set through a persistent proxy (once right, once refused)
MINROS_NODE = """
import threading
import rospy
from std_msgs.msg import String
from std_srvs.srv import SetBool, SetBoolResponse

def handle(req):
    if not req.data:
        raise rospy.ServiceException("data must be true")
    return SetBoolResponse(True, "on")

def calls():
    for name in ("rospy_set", "cpp_set"):
        rospy.wait_for_service(name, timeout=60)
        proxy = rospy.ServiceProxy(name, SetBool, persistent=True)
        proxy(True)
        try:
            proxy(False)
        except rospy.ServiceException:
            pass
        proxy.close()

rospy.init_node("minros_node")
pub = rospy.Publisher("chatter", String, queue_size=10)
for topic in ("rospy_chatter", "cpp_chatter"):
    rospy.Subscriber(topic, String, lambda msg: None)
rospy.Service("minros_set", SetBool, handle)
threading.Thread(target=calls, daemon=True).start()
rate = rospy.Rate(5)
while not rospy.is_shutdown():
    pub.publish(String("hello"))
    rate.sleep()
"""
#: minros: subscribes /chatter and makes one plain (not persistent) call
MINROS_LISTENER = """
import rospy
from std_msgs.msg import String
from std_srvs.srv import SetBool
rospy.init_node("minros_listener")
rospy.Subscriber("chatter", String, lambda msg: None)
rospy.ServiceProxy("minros_set", SetBool)(True)
rospy.spin()
"""
#: Debian's rospy: the same roles as the minros node
ROSPY_NODE = """
import threading
import rospy
from std_msgs.msg import String
from std_srvs.srv import SetBool, SetBoolResponse

def handle(req):
    if not req.data:
        raise rospy.ServiceException("data must be true")
    return SetBoolResponse(True, "on")

def calls():
    rospy.wait_for_service("minros_set", timeout=60)
    rospy.ServiceProxy("minros_set", SetBool)(True)
    proxy = rospy.ServiceProxy("minros_set", SetBool, persistent=True)
    proxy(True)
    try:
        proxy(False)
    except rospy.ServiceException:
        pass
    proxy.close()

rospy.init_node("rospy_node")
rospy.Subscriber("chatter", String, lambda msg: None)
pub = rospy.Publisher("rospy_chatter", String, queue_size=10)
rospy.Service("rospy_set", SetBool, handle)
threading.Thread(target=calls, daemon=True).start()
rate = rospy.Rate(5)
while not rospy.is_shutdown():
    pub.publish(String("hi"))
    rate.sleep()
"""
#: roscpp, compiled here against Debian's headers: the same roles again
ROSCPP_NODE = r"""
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <std_srvs/SetBool.h>

void heard(const std_msgs::String::ConstPtr&) {}

bool handle(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
  if (!req.data) return false;
  res.success = true;
  res.message = "on";
  return true;
}

int main(int argc, char** argv) {
  ros::init(argc, argv, "cpp_node");
  ros::NodeHandle n;
  ros::Subscriber sub = n.subscribe("chatter", 10, heard);
  ros::Publisher pub = n.advertise<std_msgs::String>("cpp_chatter", 10);
  ros::ServiceServer server = n.advertiseService("cpp_set", handle);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  if (ros::service::waitForService("minros_set", ros::Duration(60))) {
    std_srvs::SetBool plain;
    plain.request.data = true;
    ros::service::call("minros_set", plain);
    ros::ServiceClient client = n.serviceClient<std_srvs::SetBool>("minros_set", true);
    std_srvs::SetBool call;
    call.request.data = true;
    client.call(call);
    call.request.data = false;
    client.call(call);
  }
  ros::Rate rate(5);
  while (ros::ok()) {
    std_msgs::String msg;
    msg.data = "hi";
    pub.publish(msg);
    rate.sleep();
  }
  return 0;
}
"""
#: a subscriber whose std_msgs/String has an int32 field: every publisher refuses it
STALE = """
import rospy
from minros.msgs import generate_dynamic
Old = generate_dynamic("std_msgs/String", "int32 data")["std_msgs/String"]
rospy.init_node("stale_listener")
for topic in ("chatter", "rospy_chatter", "cpp_chatter"):
    rospy.Subscriber(topic, Old, lambda msg: None)
rospy.spin()
"""
#: every Master and Slave API call once, with the arguments ROS's clients pass
API_CALLS = """
import os, sys
import rospy
from minros.wire.xmlrpc import ServerProxy

rospy.init_node("api_probe")
me, uri = "/api_probe", rospy.get_node_uri()
master = ServerProxy(os.environ["ROS_MASTER_URI"])
for method, *args in [
        ("getUri",), ("getPid",), ("lookupNode", "/minros_node"),
        ("getPublishedTopics", ""), ("getTopicTypes",), ("getSystemState",),
        ("registerPublisher", "/probe_topic", "std_msgs/String", uri),
        ("unregisterPublisher", "/probe_topic", uri),
        ("registerSubscriber", "/probe_topic", "std_msgs/String", uri),
        ("unregisterSubscriber", "/probe_topic", uri),
        ("registerService", "/probe_service", "rosrpc://localhost:9", uri),
        ("lookupService", "/probe_service"),
        ("unregisterService", "/probe_service", "rosrpc://localhost:9"),
        ("setParam", "/probe/rate", 5), ("getParam", "/probe/rate"),
        ("hasParam", "/probe/rate"), ("searchParam", "rate"),
        ("subscribeParam", uri, "/probe/rate"), ("unsubscribeParam", uri, "/probe/rate"),
        ("getParamNames",), ("deleteParam", "/probe/rate")]:
    getattr(master, method)(me, *args)
nodes = {name: master.lookupNode(me, name)[2] for name in
         ("/minros_node", "/rospy_node", "/cpp_node", "/stale_listener")}
node = ServerProxy(nodes["/minros_node"])
for method, *args in [("getBusStats",), ("getBusInfo",), ("getMasterUri",), ("getPid",),
                      ("getSubscriptions",), ("getPublications",),
                      ("paramUpdate", "/probe/rate", 6),
                      ("publisherUpdate", "/rospy_chatter", [nodes["/rospy_node"]])]:
    getattr(node, method)(me, *args)
from minros.wire import tcpros
for name in ("/minros_node", "/rospy_node", "/cpp_node"):
    topic = {"/minros_node": "/chatter", "/rospy_node": "/rospy_chatter",
             "/cpp_node": "/cpp_chatter"}[name]
    peer = ServerProxy(nodes[name])
    udp = tcpros.encode_header({"callerid": me, "md5sum": "992ce8a1687cec8c8bd883ec73ca41d1",
                                "topic": topic, "type": "std_msgs/String"})[4:]
    peer.requestTopic(me, topic, [["UDPROS", udp, "localhost", 9, 1500], ["TCPROS"]])
    peer.requestTopic(me, topic, [["SHMROS"]])
    peer.requestTopic(me, "/no_such_topic", [["TCPROS"]])
ServerProxy(nodes["/stale_listener"]).shutdown(me, "the wire spec is written")
"""

IMPLS = ("minros", "rospy", "roscpp")
SCENARIO_NAMES = ("/chatter", "/rospy_chatter", "/cpp_chatter", "/minros_set", "/rospy_set",
                  "/cpp_set")
CALLER = {"/minros_node": "minros", "/minros_listener": "minros", "/rospy_node": "rospy",
          "/cpp_node": "roscpp"}
ROLES = (("subscriber", "topic subscriber"), ("publisher", "topic publisher"),
         ("call", "service call"), ("persistent", "persistent call"),
         ("probe", "service probe"), ("server", "service server"), ("refusal", "refusal"))


def events(path: Path) -> List[Dict[str, Any]]:
    out = []
    for line in path.read_text().splitlines():
        try:
            out.append(json.loads(line))
        except ValueError:
            pass
    return out


class Run(Session):
    """The internals session, plus processes of Debian's ROS (untraced: the minros peers
    trace what they send)."""

    def reference(self, name: str, argv: Sequence[str]) -> None:
        env = {k: v for k, v in self.env.items() if k not in ("VIRTUAL_ENV", "PYTHONHOME")}
        env["PATH"] = "/usr/bin:/bin"
        log = open(self.folder / f"{name}.log", "wb")
        self.procs[name] = subprocess.Popen(list(argv), env=env, stdout=log, stderr=log,
                                            start_new_session=True)
        log.close()

    def events(self, name: str) -> List[Dict[str, Any]]:
        return events(self.path(name))


def build_roscpp(folder: Path) -> Path:
    for tool in ("g++", "pkg-config"):
        if shutil.which(tool) is None:
            raise SystemExit(f"wire_spec_traces: {tool} is missing (scripts/install-ros-"
                             "reference.sh installs the roscpp toolchain)")
    flags = subprocess.run(["pkg-config", "--cflags", "--libs", "roscpp", "std_msgs",
                            "std_srvs"], capture_output=True, text=True, timeout=60)
    if flags.returncode:
        raise SystemExit(f"wire_spec_traces: roscpp development files: {flags.stderr.strip()}")
    source = folder / "cpp_node.cpp"
    source.write_text(ROSCPP_NODE)
    binary = folder / "cpp_node"
    done = subprocess.run(["g++", "-O1", "-o", str(binary), str(source), *flags.stdout.split()],
                          capture_output=True, text=True, timeout=600)
    if done.returncode:
        raise SystemExit(f"wire_spec_traces: compiling the roscpp node failed:\n{done.stderr}")
    return binary


# --------------------------------------------------------------------------- the run


def header_events(evs: List[Dict[str, Any]], direction: str) -> List[Dict[str, Any]]:
    return [e for e in evs if e.get("ev") == "tcpros.header" and e.get("dir") == direction]


def fields_of(ev: Dict[str, Any]) -> Dict[str, str]:
    return {k: v for k, v in ev.get("fields", [])}


def run_all(folder: Path) -> Dict[str, List[Dict[str, Any]]]:
    """Run the scenario; the events of every traced process, by name."""
    binary = build_roscpp(folder)
    s = Run(folder / "run")
    try:
        s.core()
        s.start("minros_node", [PYTHON, "-c", MINROS_NODE], messages=True)
        s.wait(lambda: s.seen("minros_node", lambda e: e.get("method") == "registerService"),
               "minros_node's service")
        s.start("minros_listener", [PYTHON, "-c", MINROS_LISTENER], messages=True)
        s.reference("rospy_node", [REFERENCE_PYTHON, "-c", ROSPY_NODE])
        s.reference("cpp_node", [str(binary)])

        def got(name: str, test: Callable[[Dict[str, Any]], bool], count: int = 1) -> bool:
            return s.count(name, test) >= count

        def header_from(caller: str, key: str, name: str) -> Callable[[Dict[str, Any]], bool]:
            return lambda e: (e.get("ev") == "tcpros.header" and e.get("dir") == "in"
                              and e.get(key) == name and fields_of(e).get("callerid") == caller)

        for caller in ("/rospy_node", "/cpp_node"):
            s.wait(lambda caller=caller: got("minros_node", header_from(
                caller, "topic", "/chatter")), f"{caller} subscribing /chatter", 60)
            s.wait(lambda caller=caller: got("minros_node", header_from(
                caller, "service", "/minros_set"), 3), f"{caller} calling /minros_set", 60)
        for topic in ("/rospy_chatter", "/cpp_chatter"):
            s.wait(lambda topic=topic: got("minros_node", lambda e: e.get(
                "ev") == "tcpros.frame" and e.get("topic") == topic), f"a frame on {topic}", 60)
        for service in ("/rospy_set", "/cpp_set"):
            s.wait(lambda service=service: got("minros_node", lambda e: e.get(
                "ev") == "tcpros.frame" and e.get("service") == service and e.get("ok") == 0),
                f"the refused call of {service}", 60)
        s.wait(lambda: got("minros_node", lambda e: e.get("ev") == "tcpros.frame"
                           and e.get("service") == "/minros_set" and e.get("dir") == "out", 7),
               "the calls of /minros_set answered", 60)
        s.start("stale_listener", [PYTHON, "-c", STALE], messages=False)
        s.wait(lambda: got("stale_listener", lambda e: e.get("ev") == "tcpros.header"
                           and "error" in fields_of(e), 3), "three refusals", 60)
        s.start("api_probe", [PYTHON, "-c", API_CALLS], messages=False)
        s.wait(lambda: s.procs["stale_listener"].poll() is not None,
               "the stale listener's shutdown", 60)
        s.stop("api_probe")
        for name in ("minros_listener", "minros_node", "rospy_node", "cpp_node"):
            s.stop(name)
        s.stop("core")
        names = ("core", "minros_node", "minros_listener", "stale_listener", "api_probe")
        out = {name: s.events(name) for name in names}
        out["_show_topic"] = [{"text": s.show(["core", "minros_node", "minros_listener"],
                                              "--topic", "/chatter", "--node",
                                              "/minros_listener", "--frames", "1")}]
        out["_show_service"] = [{"text": s.show(["core", "minros_node"], "--service",
                                                "/rospy_set", "--frames", "all")}]
        return out
    finally:
        s.close()


# --------------------------------------------------------------------------- excerpts


def hexdump_header(fields: List[List[str]]) -> List[str]:
    """A connection header's bytes, as they were on the wire, one field a line."""
    parts = [(f"{k}={v}".encode(), f"{k}={v}") for k, v in fields]
    total = sum(4 + len(raw) for raw, _ in parts)
    lines = [f"{total.to_bytes(4, 'little').hex()}{'':<44} header length: {total} bytes follow"]
    for raw, text in parts:
        text = text.replace("\n", "\\n")
        shown = raw[:20].hex() + ("…" if len(raw) > 20 else "")
        lines.append(f"{len(raw).to_bytes(4, 'little').hex()} {shown:<43} {len(raw):>3} bytes: "
                     f"{text[:60]}{'…' if len(text) > 60 else ''}")
    return lines


def headers_by_role(runs: Dict[str, List[Dict[str, Any]]]) -> Dict[Tuple[str, str],
                                                                   Dict[str, str]]:
    """(role, implementation) -> the first header of that kind the traces hold: what a minros
    process sent, and what the rospy and roscpp peers sent it."""
    from minros.learn.evidence import connections

    found: Dict[Tuple[str, str], Dict[str, str]] = {}

    def keep(role: str, fields: Dict[str, str]) -> None:
        impl = CALLER.get(fields.get("callerid", ""))
        if impl and fields and "error" not in fields and (role, impl) not in found:
            found[(role, impl)] = fields

    for name in ("minros_listener", "minros_node"):
        for conn in connections(runs[name]):
            if conn.name not in SCENARIO_NAMES:
                continue  # /rosout and the logger services every node has
            client, server = conn.client_header, conn.server_header
            if conn.kind == "topic":
                keep("subscriber", client)
                keep("publisher", server)
            elif conn.kind == "probe":
                keep("probe", client)
            elif conn.kind == "service":
                persistent = client.get("persistent", "0") not in ("0", "")
                keep("persistent" if persistent else "call", client)
                keep("server", server)
    for conn in connections(runs["stale_listener"]):
        if conn.inn.get("error"):
            impl = {"/chatter": "minros", "/rospy_chatter": "rospy",
                    "/cpp_chatter": "roscpp"}.get(conn.name)
            if impl and ("refusal", impl) not in found:
                found[("refusal", impl)] = conn.inn
    return found


def field_table(found: Dict[Tuple[str, str], Dict[str, str]]) -> str:
    keys: List[str] = []
    for fields in found.values():
        for key in fields:
            if key not in keys:
                keys.append(key)
    order = ["callerid", "topic", "service", "type", "md5sum", "message_definition",
             "tcp_nodelay", "latching", "persistent", "probe", "request_type", "response_type",
             "error"]
    keys.sort(key=lambda k: order.index(k) if k in order else len(order))
    head = "| field | " + " | ".join(f"[{title}](#{role}-headers)" for role, title in ROLES) + " |"
    lines = [head, "|---" * (len(ROLES) + 1) + "|"]
    for key in keys:
        cells = []
        for role, _title in ROLES:
            senders = [impl for impl in IMPLS if key in found.get((role, impl), {})]
            values = {found[(role, impl)][key] for impl in senders}
            flag = ""
            if len(values) == 1 and len(next(iter(values))) <= 3:
                flag = f" `{next(iter(values))}`"
            if not senders:
                cells.append("")
            elif len(senders) == len(IMPLS):
                cells.append("all" + flag)
            else:
                cells.append(", ".join(senders) + flag)
        lines.append(f"| `{key}` | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def role_headers(found: Dict[Tuple[str, str], Dict[str, str]], role: str) -> str:
    lines = []
    for impl in IMPLS:
        fields = found.get((role, impl))
        if fields is None:
            lines.append(f"{impl}: (none in this run)")
            continue
        lines.append(f"{impl}:")
        for key, value in fields.items():
            value = value.rstrip("\n")
            if "\n" in value:
                value = value.split("\n", 1)[0] + f"   (first line of {value.count(chr(10)) + 1})"
            lines.append(f"    {key}={value}")
    return "\n".join(lines)


def framing(runs: Dict[str, List[Dict[str, Any]]]) -> str:
    evs = runs["minros_listener"]
    header = next(e for e in header_events(evs, "out") if e.get("topic") == "/chatter")
    answer = next(e for e in header_events(evs, "in") if e.get("topic") == "/chatter")
    frame = next(e for e in evs if e.get("ev") == "tcpros.frame" and e.get("topic") == "/chatter")
    body = bytes.fromhex(frame["head"])
    lines = ["the subscriber's connection header (it speaks first):"]
    lines += ["  " + line for line in hexdump_header(header["fields"])]
    lines += ["the publisher's answer:"]
    lines += ["  " + line for line in hexdump_header(answer["fields"])]
    lines += ["then each message, back to back:",
              f"  {frame['len'].to_bytes(4, 'little').hex()}  frame length: {frame['len']} bytes "
              "follow",
              f"  {body[:4].hex()}  std_msgs/String's one field: a string of "
              f"{int.from_bytes(body[:4], 'little')} bytes",
              f"  {body[4:].hex()}  {body[4:].decode()!r}"]
    return "\n".join(lines)


def service_frames(runs: Dict[str, List[Dict[str, Any]]]) -> str:
    """Each server's two answers on a persistent connection: ok=1 and a response, ok=0 and
    an error text."""
    from minros.learn.evidence import connections

    lines = []
    evs = runs["minros_node"]
    for service, impl in (("/minros_set", "minros"), ("/rospy_set", "rospy"),
                          ("/cpp_set", "roscpp")):
        frames: List[Dict[str, Any]] = []
        for conn in connections(evs, service=service):
            if conn.client_header.get("persistent") not in ("1", "true"):
                continue
            if conn.side == "connect":
                frames = conn.frames_in
            elif conn.client_header.get("callerid") == "/rospy_node":
                frames = conn.frames_out
        lines.append(f"{impl} server ({service}), two calls on one persistent connection:")
        for e in frames[:2]:
            ok = e.get("ok", -1)
            body = bytes.fromhex(e["head"])
            if ok:
                what = "= " + json.dumps(e.get("msg"))
            else:
                what = "error text " + json.dumps(body.decode("utf-8", "replace"))
            prefix = bytes([ok]).hex() + " " + e["len"].to_bytes(4, "little").hex()
            lines.append(f"    {prefix}  ok={ok}, {e['len']} bytes: {body[:24].hex()}"
                         f"{'…' if len(body) > 24 else ''}")
            lines.append(f"    {'':<13}  {what}")
    return "\n".join(lines)


def refusals(found: Dict[Tuple[str, str], Dict[str, str]]) -> str:
    lines = []
    for impl in IMPLS:
        error = found.get(("refusal", impl), {}).get("error", "(none)")
        lines.append(f"{impl}:\n    error={error}")
    return "\n".join(lines)


#: answers that list the graph: shown by their first entry (sorted), the rest elided
SAMPLED = ("getPublishedTopics", "getTopicTypes", "getSystemState", "getParamNames",
           "getSubscriptions", "getPublications", "getBusInfo", "getBusStats")


def _sorted(value: Any) -> Any:
    """Lists of names sorted, all the way down (the order of registrations is a race);
    other lists keep their order."""
    if isinstance(value, list):
        items = [_sorted(item) for item in value]
        return sorted(items) if all(isinstance(item, str) for item in items) else items
    return value


def _first(value: Any) -> Any:
    """A list reduced to its first entry (sorted, so that runs agree) and an ellipsis."""
    if isinstance(value, list) and value:
        return [sorted(_sorted(value), key=json.dumps)[0], "…"]
    return value


def _arg(value: Any) -> str:
    """One argument or answer value as JSON; binary data (a trace keeps its first bytes) by
    its size."""
    if isinstance(value, dict) and "len" in value and ("hex" in value or "base64" in value):
        return f"<{value['len']} bytes>"
    if isinstance(value, list):
        return "[" + ", ".join(_arg(item) for item in value) + "]"
    return json.dumps(value, ensure_ascii=False)


def _masked(value: Any) -> Any:
    """Counts and connection ids, which change from run to run, as N."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int):
        return "N"
    if isinstance(value, list):
        return [_masked(item) for item in value]
    return value


def _call_line(ev: Dict[str, Any], width: int = 110) -> str:
    method = ev["method"]
    args = ", ".join(_arg(a) for a in ev.get("args", []))
    reply = ev.get("reply")
    if isinstance(reply, list) and len(reply) == 3:
        value = reply[2]
        if method in ("getBusStats", "getBusInfo"):
            value = _masked(value)
        if isinstance(value, list) and value[:1] == ["UDPROS"] and len(value) > 3:
            value = [*value[:3], "N", *value[4:]]  # roscpp's connection id: a counter
        if method in ("getSystemState", "getBusStats") and isinstance(value, list):
            value = [_first(part) for part in value]
        elif method in SAMPLED:
            value = _first(value)
        text = _arg(value).replace('"…"', "…").replace('"N"', "N")
        if len(text) > width:
            text = text[:width - 1] + "…"
        answer = f"{reply[0]}, {json.dumps(reply[1])}, {text}"
    else:
        answer = ev.get("fault") or ev.get("error") or json.dumps(reply)
    return f"{method}({args})\n    <- {answer}"


def _node_uris(evs: List[Dict[str, Any]]) -> Dict[str, str]:
    """URI -> node name, from the lookupNode answers of a trace."""
    out = {}
    for ev in evs:
        reply = ev.get("reply")
        if ev.get("method") == "lookupNode" and isinstance(reply, list) and reply[0] == 1:
            out[str(reply[2])] = str(ev["args"][1])
    return out


def negotiation(runs: Dict[str, List[Dict[str, Any]]]) -> str:
    nodes = _node_uris(runs["api_probe"])
    impl = {"/minros_node": "minros", "/rospy_node": "rospy", "/cpp_node": "roscpp"}
    lines = []
    for ev in runs["api_probe"]:
        if ev.get("ev") == "xmlrpc.call" and ev.get("method") == "requestTopic":
            name = nodes.get(str(ev.get("uri")), "?")
            lines.append(f"to {name} ({impl.get(name, '?')}): " + _call_line(ev, width=200))
    return "\n".join(lines)


def api_calls(runs: Dict[str, List[Dict[str, Any]]]) -> str:
    """The probe's own calls (not those its client library made on init_node and shutdown),
    the Master API's then a node's Slave API."""
    evs = [ev for ev in runs["api_probe"] if ev.get("ev") == "xmlrpc.call"]
    start = next(i for i, ev in enumerate(evs) if ev.get("method") == "getUri")
    nodes = _node_uris(evs)
    master, slave = [], []
    for ev in evs[start:]:
        if ev["method"] in ("requestTopic", "system.multicall"):
            continue
        if ev["method"] == "shutdown":
            slave.append("(to /stale_listener) " + _call_line(ev))
        elif str(ev.get("uri")) in nodes:
            slave.append(_call_line(ev))
        elif not slave and not any(line.startswith(ev["method"] + "(") for line in master):
            master.append(_call_line(ev))
    return "\n".join(["Master API, to the master:", *master, "",
                      "Slave API, to /minros_node:", *slave])


def excerpts(folder: Path) -> Dict[str, str]:
    runs = run_all(folder)
    found = headers_by_role(runs)
    fence = "```text\n{}\n```\n"
    topic = sections_only(runs["_show_topic"][0]["text"])
    topic_lines = [line for line in topic if "frames received" not in line
                   and "more frames" not in line]
    service = sections_only(runs["_show_service"][0]["text"])
    # the lookups before the server registered are a race: the excerpt starts at [0]
    first = next(i for i, line in enumerate(service) if "registerService(" in line)
    service = service[:1] + service[first:]
    out = {
        "framing": fence.format(framing(runs)),
        "field-table": field_table(found) + "\n",
        "topic-sequence": fence.format("\n".join(topic_lines)),
        "service-sequence": fence.format("\n".join(service)),
        "ok-byte": fence.format(service_frames(runs)),
        "refusals": fence.format(refusals(found)),
        "negotiation": fence.format(negotiation(runs)),
        "api": fence.format(api_calls(runs)),
    }
    for role, _title in ROLES[:-1]:
        out[f"{role}-headers"] = fence.format(role_headers(found, role))
    return out


# --------------------------------------------------------------------------- the doc


def wire_normalize(text: str) -> str:
    """What differs between two runs: ports, pids, times (``normalize``), and the values
    that carry them (URIs in lists, process ids in answers, times in messages)."""
    text = normalize(text)
    rules = [
        (r"(getPid\([^)]*\)\n\s+<- 1, \"[^\"]*\", )\d+", r"\1PID"),
        (r'"(?:localhost|127\.0\.0\.1)", \d+', '"localhost", PORT'),
        (r"\bport \d+", "port PORT"),
        (r"\bsocket \d+", "socket N"),
        (r"… \d+ more frames, \d+ bytes", "… N more frames, B bytes"),
    ]
    for pattern, replacement in rules:
        text = re.sub(pattern, replacement, text, flags=re.M)
    return text


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", action="store_true", help="rewrite the excerpts in the doc")
    mode.add_argument("--check", action="store_true", help="exit 1 when the doc disagrees")
    args = parser.parse_args(argv)
    if not os.path.exists(REFERENCE_PYTHON):
        raise SystemExit("wire_spec_traces: Debian's ROS 1 is needed (scripts/install-ros-"
                         "reference.sh)")
    doc = DOC.read_text()
    names = [m.group("name") for m in BLOCK.finditer(doc)]
    with tempfile.TemporaryDirectory(prefix="wire-spec-") as tmp:
        made = excerpts(Path(tmp))
    unknown = sorted(set(names) - set(made))
    if unknown:
        print(f"wire_spec_traces: the doc has blocks no scenario makes: {unknown}",
              file=sys.stderr)
        return 1
    if args.write:
        DOC.write_text(BLOCK.sub(lambda m: m.group(1) + made[m.group("name")] + m.group(4), doc))
        print(f"wrote {len(names)} excerpts into {DOC.relative_to(REPO)}")
        return 0
    status = 0
    # every call the API tables describe is in an excerpt: the table's claims are linked
    shown = "\n".join(made.values())
    for method in re.findall(r"^\| `(\w+)\(", doc, re.M):
        if f"{method}(" not in shown:
            status = 1
            print(f"docs/wire.md describes {method}, which no excerpt shows")
    for match in BLOCK.finditer(doc):
        name = match.group("name")
        have, want = wire_normalize(match.group("body")), wire_normalize(made[name])
        if have != want:
            status = 1
            print(f"docs/wire.md, block {name!r} differs from this run "
                  "(regenerate: scripts/wire_spec_traces.py --write):")
            sys.stdout.writelines(difflib.unified_diff(
                have.splitlines(True), want.splitlines(True), "docs/wire.md", "this run"))
            print()
    if not status:
        print(f"docs/wire.md: {len(names)} excerpts agree with this run")
    return status


if __name__ == "__main__":
    sys.exit(main())
