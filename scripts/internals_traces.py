#!/usr/bin/env python3
"""Regenerate, or check, the trace excerpts of docs/internals.md from real runs.

    .venv/bin/python scripts/internals_traces.py --write    rewrite the excerpts in the doc
    .venv/bin/python scripts/internals_traces.py --check    exit 1 when the doc disagrees

Every block of the doc between ``<!-- trace: NAME -->`` and ``<!-- /trace -->`` is the output
of ``minros trace show`` for one scenario, run here on real processes: a traced ``minros core``,
the talker and listener of examples/, the add_two_ints tutorial and a few small nodes written
below for the failure stories. ``--check`` compares them with what this run printed, ignoring
what changes from one run to the next: ports, pids, times, how many times a repeated call was
made, how many frames went by. tests/integration/test_internals_doc.py runs ``--check``.
"""

from __future__ import annotations

import argparse
import difflib
import json
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable, Dict, List, Optional, Sequence

REPO = Path(__file__).resolve().parent.parent
DOC = REPO / "docs" / "internals.md"
EXAMPLES = REPO / "examples"
PYTHON = sys.executable
BLOCK = re.compile(r"(<!-- trace: (?P<name>[\w-]+) -->\n```text\n)(?P<body>.*?)(```\n<!-- /trace -->)",
                   re.S)

#: a subscriber built from an older std_msgs/String whose one field was an int32: the same type
#: name, another definition, so another md5sum (what a stale build does)
STALE_SUBSCRIBER = """
import rospy
from minros.msgs import generate_dynamic
OldString = generate_dynamic("std_msgs/String", "int32 data")["std_msgs/String"]
rospy.init_node("old_listener")
rospy.Subscriber("greetings", OldString, lambda msg: None)
rospy.spin()
"""
#: a node that only publishes: started twice under one name for the name collision
CAMERA = """
import rospy
from std_msgs.msg import String
rospy.init_node("camera")
rospy.Publisher("images", String, queue_size=1)
rospy.spin()
"""
#: a subscriber, asking for TCP_NODELAY or not (argv: topic, 0 or 1)
NAGLE_LISTENER = """
import sys
import rospy
from std_msgs.msg import String
topic, nodelay = sys.argv[1], sys.argv[2] == "1"
rospy.init_node("listener_" + topic)
rospy.Subscriber(topic, String, lambda msg: None, tcp_nodelay=nodelay)
rospy.spin()
"""
#: 400 messages of 1000 bytes at 400 Hz, once a subscriber is there (argv: topic)
NAGLE_SENSOR = """
import sys
import rospy
from std_msgs.msg import String
topic = sys.argv[1]
rospy.init_node("sensor_" + topic)
pub = rospy.Publisher(topic, String, queue_size=100)
while pub.get_num_connections() == 0:
    rospy.sleep(0.01)
rate = rospy.Rate(400)
for i in range(400):
    pub.publish("x" * 996)
    rate.sleep()
"""


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class Session:
    """A master on a free port, and processes each traced to its own file."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.port = _free_port()
        home = folder / "ros_home"
        (home / "log").mkdir(parents=True, exist_ok=True)
        self.env = {k: v for k, v in os.environ.items()
                    if not k.startswith(("ROS_", "MINROS_")) and k != "PYTHONPATH"}
        self.env.update(ROS_MASTER_URI=f"http://localhost:{self.port}", ROS_HOSTNAME="localhost",
                        ROS_HOME=str(home), ROS_LOG_DIR=str(home / "log"),
                        PYTHONUNBUFFERED="1", MINROS_HEADLESS="1",
                        # the page teaches TCPROS: two minros nodes of one host would take
                        # shared memory (MINROSSHM, README "Shared memory")
                        MINROS_SHM="0")
        self.procs: Dict[str, subprocess.Popen] = {}

    def path(self, name: str) -> Path:
        return self.folder / f"{name}.jsonl"

    def start(self, name: str, argv: Sequence[str], messages: bool = True) -> subprocess.Popen:
        command = [PYTHON, "-m", "minros", "trace", "-o", str(self.path(name))]
        command += ["--messages"] if messages else []
        proc = subprocess.Popen([*command, "--", *argv], env=self.env, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL, start_new_session=True)
        self.procs[name] = proc
        return proc

    def core(self, name: str = "core") -> None:
        self.start(name, [PYTHON, "-m", "minros", "core", "-p", str(self.port)], messages=False)
        self.wait(lambda: self._master_up(), f"the master on port {self.port}")

    def _master_up(self) -> bool:
        import xmlrpc.client

        try:
            return xmlrpc.client.ServerProxy(
                f"http://127.0.0.1:{self.port}/").getPid("/internals")[0] == 1
        except OSError:
            return False

    def seen(self, name: str, predicate: Callable[[dict], bool]) -> bool:
        try:
            lines = self.path(name).read_text().splitlines()
        except OSError:
            return False
        for line in lines:
            try:
                ev = json.loads(line)
            except ValueError:
                continue
            if predicate(ev):
                return True
        return False

    def count(self, name: str, predicate: Callable[[dict], bool]) -> int:
        try:
            lines = self.path(name).read_text().splitlines()
        except OSError:
            return 0
        return sum(1 for line in lines if predicate(json.loads(line)))

    @staticmethod
    def wait(predicate: Callable[[], bool], what: str, timeout: float = 20.0) -> None:
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline:
                raise SystemExit(f"internals_traces: {what} did not happen within {timeout:g} s")
            time.sleep(0.05)

    def stop(self, name: str) -> None:
        """Ctrl-C, as a user stops a node (it then closes its connections: the trace says
        so); SIGTERM and SIGKILL only for one that hangs."""
        proc = self.procs.pop(name)
        for sig, grace in ((signal.SIGINT, 15), (signal.SIGTERM, 5), (signal.SIGKILL, 5)):
            if proc.poll() is not None:
                return
            try:
                os.killpg(proc.pid, sig)
            except ProcessLookupError:
                return
            try:
                proc.wait(grace)
            except subprocess.TimeoutExpired:
                continue

    def finish(self, name: str, timeout: float = 30.0) -> None:
        """Wait for a process that ends by itself."""
        try:
            self.procs[name].wait(timeout)
        except subprocess.TimeoutExpired:
            pass
        self.stop(name)

    def close(self) -> None:
        for name in list(self.procs):
            self.stop(name)

    def show(self, names: Sequence[str], *args: str) -> str:
        files = [str(self.path(n)) for n in names]
        done = subprocess.run([PYTHON, "-m", "minros", "trace", "show", *args, *files],
                              env=self.env, capture_output=True, text=True, timeout=60)
        if done.returncode:
            raise SystemExit(f"internals_traces: minros trace show failed: {done.stderr}")
        return done.stdout


# --------------------------------------------------------------------------- excerpts


def sections_only(text: str) -> List[str]:
    """Drop the legend, the run heading and the closing note: only the sections."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines)
                 if line.startswith(("topic ", "service ", "other XML-RPC calls")))
    body = lines[start:]
    while body and (not body[-1].strip() or body[-1].startswith("not shown")):
        body.pop()
    # who closes a connection first is a race between two processes: not in the excerpts
    return [line for line in body
            if "closed the connection" not in line and "saw the peer close" not in line]


def until(lines: List[str], pattern: str, occurrence: int = 1, extra: int = 0) -> List[str]:
    """``lines`` up to the ``occurrence``-th line matching ``pattern`` and ``extra`` more."""
    seen = 0
    for i, line in enumerate(lines):
        if re.search(pattern, line):
            seen += 1
            if seen == occurrence:
                return lines[:i + 1 + extra]
    raise SystemExit(f"internals_traces: no {pattern!r} in:\n" + "\n".join(lines))


def frame_block(lines: List[str], start: int) -> int:
    """How many lines the item starting at ``start`` has (its continuation lines)."""
    n = 1
    while start + n < len(lines) and re.match(r"^\s{10,}\S", lines[start + n]) and not re.match(
            r"^\s*\[\d\]\s+\+", lines[start + n]):
        n += 1
    return n


def through_frame(lines: List[str], number: int) -> List[str]:
    """``lines`` up to and including message ``number`` with its body lines."""
    for i, line in enumerate(lines):
        if re.search(rf"(message|request|response) {number}:", line):
            return lines[:i + frame_block(lines, i)]
    raise SystemExit(f"internals_traces: no frame {number} in:\n" + "\n".join(lines))


def only_calls(lines: List[str], keep: Sequence[str], drop: str = "") -> List[str]:
    """``lines`` with the "other XML-RPC calls" section reduced to the calls named in
    ``keep`` whose lines do not mention ``drop`` (each call is a line with a time and the
    lines under it)."""
    try:
        start = lines.index("other XML-RPC calls (parameters, graph queries, probes, shutdown)")
    except ValueError:
        return lines
    entries: List[List[str]] = []
    for line in lines[start + 1:]:
        if re.match(r"^\s*[+-]\d+\.\d{3}\s", line) or not entries:
            entries.append([])
        entries[-1].append(line)
    kept = [entry for entry in entries if any(word in entry[0] for word in keep)
            and not (drop and any(drop in line for line in entry))]
    return lines[:start + 1] + [line for entry in kept for line in entry]


def scenarios(folder: Path) -> Dict[str, str]:
    """Run every scenario; the excerpt of each, by block name."""
    out: Dict[str, str] = {}
    talker = str(EXAMPLES / "talker_listener/talker.py")
    listener = str(EXAMPLES / "talker_listener/listener.py")
    s = Session(folder / "main")
    try:
        s.core()
        on = s.seen

        # the course's order: the talker registers, then the listener
        s.start("talker", [PYTHON, talker, "--wait", "--count", "3"])
        s.wait(lambda: on("talker", lambda e: e.get("method") == "registerPublisher"
                          and e["args"][1] == "/chatter"), "the talker's registration")
        s.start("listener", [PYTHON, listener, "--count", "3"])
        s.finish("listener")
        s.finish("talker")
        lines = sections_only(s.show(["core", "talker", "listener"], "--topic", "/chatter",
                                     "--frames", "2"))
        out["talker-listener"] = "\n".join(through_frame(lines, 2))

        # the listener first: the master calls it back with publisherUpdate
        s.start("reader", [PYTHON, listener, "--count", "1", "chatter:=news", "__name:=reader"])
        s.wait(lambda: on("reader", lambda e: e.get("method") == "registerSubscriber"
                          and e["args"][1] == "/news"), "the reader's registration")
        s.start("writer", [PYTHON, talker, "--wait", "--count", "1", "chatter:=news",
                           "__name:=writer"])
        s.finish("reader")
        s.finish("writer")
        lines = sections_only(s.show(["core", "reader", "writer"], "--topic", "/news"))
        out["listener-first"] = "\n".join(until(lines, r"^\s*\[4\]"))

        # a service and a client (the tutorial's, unmodified)
        s.start("server", [PYTHON, str(EXAMPLES / "add_two_ints/add_two_ints_server.py")])
        s.wait(lambda: on("server", lambda e: e.get("method") == "registerService"
                          and e["args"][1] == "/add_two_ints"), "the service's registration")
        s.start("client", [PYTHON, str(EXAMPLES / "add_two_ints/add_two_ints_client.py"), "4", "5"])
        s.finish("client")
        s.stop("server")
        lines = sections_only(s.show(["core", "server", "client"], "--service", "/add_two_ints",
                                     "--frames", "all"))
        out["service"] = "\n".join(until(lines, r"response 1:", 1, 2))

        # a stale build: same type name, another md5sum
        s.start("greeter", [PYTHON, talker, "--count", "100", "chatter:=greetings",
                            "__name:=greeter"])
        s.wait(lambda: on("greeter", lambda e: e.get("method") == "registerPublisher"
                          and e["args"][1] == "/greetings"), "the greeter's registration")
        s.start("old_listener", [PYTHON, "-c", STALE_SUBSCRIBER])
        s.wait(lambda: on("old_listener", lambda e: e["ev"] == "tcpros.header" and e["dir"] == "in"
                          and any(k == "error" for k, _v in e["fields"])), "the refusal")
        s.stop("old_listener")
        s.stop("greeter")
        lines = sections_only(s.show(["core", "greeter", "old_listener"], "--topic",
                                     "/greetings", "--node", "/old_listener"))
        out["md5-mismatch"] = "\n".join(until(lines, r"connection header \(refusal\)", 1, 1))

        # two nodes, one name
        s.start("camera1", [PYTHON, "-c", CAMERA])
        s.wait(lambda: on("camera1", lambda e: e.get("method") == "registerPublisher"
                          and e["args"][1] == "/images"), "the first camera's registration")
        s.start("camera2", [PYTHON, "-c", CAMERA])
        s.wait(lambda: s.procs["camera1"].poll() is not None, "the first camera's shutdown")
        s.stop("camera2")
        lines = sections_only(s.show(["core", "camera1", "camera2"], "--node", "/camera"))
        out["name-collision"] = "\n".join(until(lines, r"shutdown\(", 1, 1))

        # 1000-byte messages at 400 Hz, to a subscriber without and with TCP_NODELAY
        nagle: List[str] = []
        for topic, nodelay in (("nagle", "0"), ("nodelay", "1")):
            s.start(f"listener_{topic}", [PYTHON, "-c", NAGLE_LISTENER, topic, nodelay],
                    messages=False)
            s.wait(lambda topic=topic: on(f"listener_{topic}", lambda e: e.get(
                "method") == "registerSubscriber" and e["args"][1] == f"/{topic}"),
                f"the {topic} listener's registration")
            s.start(f"sensor_{topic}", [PYTHON, "-c", NAGLE_SENSOR, topic], messages=False)
            s.finish(f"sensor_{topic}")
            s.stop(f"listener_{topic}")
            lines = sections_only(s.show(["core", f"listener_{topic}", f"sensor_{topic}"],
                                         "--topic", f"/{topic}", "--frames", "0"))
            start = next(i for i, line in enumerate(lines) if "connection header" in line)
            nagle += lines[start:start + 7]
            nagle += [line for line in lines if "frames received" in line] + [""]
        out["nagle"] = "\n".join(nagle[:-1])
    finally:
        s.close()

    # the master restarts under a talker and a listener
    r = Session(folder / "restart")
    try:
        r.core("core1")
        r.start("talker", [PYTHON, talker, "--wait"])
        r.wait(lambda: r.seen("talker", lambda e: e.get("method") == "registerPublisher"),
               "the talker's registration")
        r.start("listener", [PYTHON, listener])
        r.wait(lambda: r.count("listener", lambda e: e["ev"] == "tcpros.frame"
                               and e.get("topic") == "/chatter") >= 2, "two messages")
        r.stop("core1")
        def refused(e: dict) -> bool:
            return e.get("method") == "getPid" and "Connection refused" in e.get("error", "")

        r.wait(lambda: r.seen("talker", refused) and r.seen("listener", refused),
               "both nodes losing the master")
        r.core("core2")
        def again(e: dict) -> bool:
            return (e.get("method") in ("registerPublisher", "registerSubscriber")
                    and e["args"][1] == "/chatter" and "reply" in e)

        r.wait(lambda: r.count("talker", again) >= 2 and r.count("listener", again) >= 2,
               "both nodes registering again")
        r.stop("listener")
        r.stop("talker")
        r.stop("core2")
        lines = sections_only(r.show(["core1", "core2", "talker", "listener"], "--node", "/talker",
                                     "--frames", "1"))
        # a probe on the kept-alive connection the old master closed fails first with
        # "connection closed by the server", or not, depending on which end noticed first
        out["master-restart"] = "\n".join(only_calls(lines, ("getPid(",), drop="_PeerClosed"))
    finally:
        r.close()
    return out


# --------------------------------------------------------------------------- the doc


def normalize(text: str) -> str:
    """What may differ between two runs of the same scenario, masked."""
    rules = [
        (r" *[+-]\d+\.\d{3}\b", " +T"),  # with its padding: +9.889 and +12.860 differ in width
        (r"\b(localhost|127\.0\.0\.1|\[::1\]):\d+", r"\1:PORT"),
        (r'"localhost", \d+', '"localhost", PORT'),
        # whether a call was repeated (a probe during an outage, a log line) is timing
        (r"^\s*\(and \d+ more times?, the last at [^)]*\)$\n?", ""),
        (r"… \d+ more frames, \d+ bytes", "… N more frames, B bytes"),
        # latencies are measured, not fixed
        (r"\d+ frames received \d+\.\d+ ms after they were sent \(median\), 90% within "
         r"\d+\.\d+ ms, max \d+\.\d+ ms", "N frames received after X ms (median), 90% within Y ms, "
         "max Z ms"),
        (r"received \d+\.\d+ ms later", "received X ms later"),
        # which node re-registers first after the master restarts is a race: its answer lists
        # the other one or not
        (r'(as (?:publisher|subscriber) of \[/chatter\]|Subscribed to \[/chatter\])", \[[^\]]*\]',
         r'\1", [...]'),
        (r"[ \t]+$", ""),
    ]
    for pattern, replacement in rules:
        text = re.sub(pattern, replacement, text, flags=re.M)
    return text.strip("\n")


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", action="store_true", help="rewrite the excerpts in the doc")
    mode.add_argument("--check", action="store_true", help="exit 1 when the doc disagrees")
    args = parser.parse_args(argv)
    doc = DOC.read_text()
    names = [m.group("name") for m in BLOCK.finditer(doc)]
    with tempfile.TemporaryDirectory(prefix="internals-") as tmp:
        excerpts = scenarios(Path(tmp))
    unknown = sorted(set(names) - set(excerpts))
    if unknown:
        print(f"internals_traces: the doc has blocks no scenario makes: {unknown}", file=sys.stderr)
        return 1
    if args.write:
        DOC.write_text(BLOCK.sub(lambda m: m.group(1) + excerpts[m.group("name")] + "\n"
                                 + m.group(4), doc))
        print(f"wrote {len(names)} excerpts into {DOC.relative_to(REPO)}")
        return 0
    status = 0
    for match in BLOCK.finditer(doc):
        name = match.group("name")
        have, want = normalize(match.group("body").rstrip("\n")), normalize(excerpts[name])
        if have != want:
            status = 1
            print(f"docs/internals.md, block {name!r} differs from this run "
                  "(regenerate: scripts/internals_traces.py --write):")
            sys.stdout.writelines(difflib.unified_diff(
                have.splitlines(True), want.splitlines(True), "docs/internals.md", "this run"))
            print()
    if not status:
        print(f"docs/internals.md: {len(names)} excerpts agree with this run")
    return status


if __name__ == "__main__":
    sys.exit(main())
