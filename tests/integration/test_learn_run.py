"""``minros learn`` end to end: each exercise started as a learner starts it, worked through by
a scripted learner in "another terminal" (the traced commands the task prints, reading the
answer from ``minros trace show`` as a person would), checked with a wrong answer (a hint)
and the right one, then stopped with Ctrl-C, which ends every process it started."""

from __future__ import annotations

import hashlib
import json
import os
import re
import signal
import socket
import struct
import subprocess
from pathlib import Path
from typing import List, Optional

import pytest

from support import PYTHON, Proc, wait_until
from zenoh_support import require_zenoh


def _events(path: Path) -> List[dict]:
    try:
        lines = path.read_text().splitlines()
    except OSError:
        return []
    out = []
    for line in lines:
        try:
            out.append(json.loads(line))
        except ValueError:
            pass  # a line being written
    return out


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


class Learner:
    """``minros learn N`` in one terminal, the learner's commands in another."""

    def __init__(self, tmp_path: Path, number: int, *extra: str) -> None:
        self.number = number
        self.base = tmp_path / "learn"
        home = tmp_path / "ros_home"
        (home / "log").mkdir(parents=True, exist_ok=True)
        self.env = {k: v for k, v in os.environ.items()
                    if not k.startswith(("ROS_", "MINROS_")) and k != "PYTHONPATH"}
        self.env.update(ROS_HOME=str(home), PYTHONUNBUFFERED="1")
        self.proc = Proc([PYTHON, "-m", "minros", "learn", str(number), "--dir", str(self.base),
                          "--seed", "7", *extra], self.env)
        self.task = self.proc.read_until("Ctrl-C here stops the exercise", 90)
        self.folder = next(self.base.glob(f"{number:02d}-*"))
        self.facts = json.loads((self.folder / "state.json").read_text())
        # the other terminal: `source env.sh`
        for line in (self.folder / "env.sh").read_text().splitlines():
            if line.startswith("export "):
                key, _, value = line[len("export "):].partition("=")
                self.env[key] = value

    def path(self, name: str) -> Path:
        return self.folder / name

    def run(self, *argv: str, timeout: float = 60) -> subprocess.CompletedProcess:
        return subprocess.run([PYTHON, "-m", "minros", *argv], env=self.env, capture_output=True,
                              text=True, timeout=timeout, cwd=self.folder)

    def traced(self, trace: str, *argv: str, timeout: float = 60) -> subprocess.CompletedProcess:
        """A command that ends by itself, traced into the folder."""
        done = self.run("trace", "-o", str(self.path(trace)), "--", PYTHON, "-m", "minros",
                        *argv, timeout=timeout)
        assert done.returncode == 0, done.stdout + done.stderr
        return done

    def traced_until(self, trace: str, argv: List[str], until, what: str,
                     timeout: float = 30) -> None:
        """A command the learner stops with Ctrl-C once its trace shows ``until``."""
        proc = Proc([PYTHON, "-m", "minros", "trace", "-o", str(self.path(trace)), "--",
                     *argv], self.env)
        try:
            wait_until(lambda: until(_events(self.path(trace))), timeout, what=what)
        finally:
            proc.stop()

    def show(self, *args: str) -> str:
        done = self.run("trace", "show", *args)
        assert done.returncode == 0, done.stderr
        return done.stdout

    def check(self, *answer: str):
        done = self.run("learn", "check", str(self.number), "--dir", str(self.base), *answer)
        return done.returncode, done.stdout + done.stderr

    def wrong_then_right(self, wrong: List[str], hint: str, right: List[str]) -> str:
        code, out = self.check(*wrong)
        assert code == 1 and out.startswith("not yet:") and "\nhint: " in out, out
        assert hint in out, out
        code, out = self.check(*right)
        assert code == 0 and out.startswith("Right"), out
        return out

    def stop(self) -> str:
        pids = list(self.facts.get("pids", {}).values())
        self.proc.popen.send_signal(signal.SIGINT)
        assert self.proc.popen.wait(30) == 0
        out = self.proc.output()
        assert "stopped; your traces stay in" in out
        assert not [pid for pid in pids if _alive(pid)], "minros learn left processes behind"
        return out


@pytest.fixture
def learner(tmp_path):
    made: List[Learner] = []

    def start(number: int, *extra: str) -> Learner:
        made.append(Learner(tmp_path, number, *extra))
        return made[-1]

    yield start
    for item in made:
        item.proc.stop()


def _frames_in(topic: str, count: int = 1):
    return lambda events: sum(1 for e in events if e.get("ev") == "tcpros.frame"
                              and e.get("dir") == "in" and e.get("topic") == topic) >= count


def _header_in(topic: str):
    return lambda events: any(e.get("ev") == "tcpros.header" and e.get("dir") == "in"
                              and e.get("topic") == topic for e in events)


def test_1_the_masters_answer_to_register_subscriber(learner):
    me = learner(1)
    assert "minros learn check 1 URI..." in me.task
    me.traced("me.jsonl", "topic", "echo", "-n", "1", "/chatter")
    shown = me.show(str(me.path("me.jsonl")), "--topic", "/chatter")
    uri = re.search(r'<- 1, "Subscribed to \[/chatter\]", \["([^"]+)"\]', shown).group(1)
    port = re.search(r'\["TCPROS", "localhost", (\d+)\]', shown).group(1)
    me.wrong_then_right([f"localhost:{port}"], "never knows data ports", [uri])
    # a second start of the same exercise is refused while this one runs
    again = subprocess.run([PYTHON, "-m", "minros", "learn", "1", "--dir", str(me.base)],
                           env=me.env, capture_output=True, text=True, timeout=60)
    assert again.returncode == 1 and "already running" in again.stderr
    me.stop()


def test_2_both_connection_headers(learner):
    me = learner(2)
    me.traced("me.jsonl", "topic", "echo", "-n", "1", "/chatter")
    shown = me.show(str(me.path("me.jsonl")), "--topic", "/chatter")
    headers = re.findall(r"connection header: .*?\n((?:\s+\w+=.*\n)+)", shown)
    mine, theirs = ({line.strip().split("=")[0] for line in block.splitlines()}
                    for block in headers[:2])
    only_mine, only_theirs = sorted(mine - theirs), sorted(theirs - mine)
    assert (only_mine, only_theirs) == (["tcp_nodelay"], ["latching"])
    me.wrong_then_right(only_theirs + only_mine, "the subscriber speaks first",
                        only_mine + only_theirs)
    me.stop()


def test_3_the_listener_first_publisher_update(learner):
    me = learner(3)
    me.traced("me.jsonl", "topic", "pub", "-1", "/news", "std_msgs/String", "data: hi")
    shown = me.show(*map(str, sorted(me.folder.glob("*.jsonl"))), "--topic", "/news")
    uri = re.search(r'publisherUpdate\("/master", "/news", \["([^"]+)"\]\)', shown).group(1)
    me.wrong_then_right(["registerPublisher", uri], "your node's call to the master",
                        ["publisherUpdate", uri])
    me.stop()


def test_4_a_frame_byte_by_byte(learner):
    me = learner(4)
    me.traced_until("me.jsonl", [PYTHON, "-m", "minros", "topic", "hz", "/temperature"],
                    _frames_in("/temperature"), "a frame on /temperature")
    shown = me.show(str(me.path("me.jsonl")), "--topic", "/temperature", "--frames", "1")
    body = bytes.fromhex(re.search(r"body ([0-9a-f ]+)", shown).group(1).replace(" ", ""))
    # by hand: seq, secs, nsecs, then the string's length and bytes, then two float64
    (length,) = struct.unpack_from("<I", body, 12)
    frame_id = body[16:16 + length].decode()
    (temperature,) = struct.unpack_from("<d", body, 16 + length)
    (wrong,) = struct.unpack_from(">d", body, 16 + length)
    assert (frame_id, temperature) == (me.facts["frame_id"], me.facts["temperature"])
    out = me.wrong_then_right([frame_id, repr(wrong)], "little-endian",
                              [frame_id, repr(temperature)])
    assert f'header.frame_id = "{frame_id}"' in out
    me.stop()


def test_5_an_md5sum_by_hand(tmp_path):
    base = tmp_path / "learn"
    done = subprocess.run([PYTHON, "-m", "minros", "learn", "5", "--dir", str(base), "--seed",
                           "3"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and "nothing to keep running" in done.stdout, done.stderr
    msg = (base / "05-md5sum" / "Reading.msg").read_text()
    header = subprocess.run([PYTHON, "-m", "minros", "msg", "md5", "std_msgs/Header"],
                            capture_output=True, text=True, timeout=60).stdout.strip()
    lines = [line.split("#")[0].strip() for line in msg.splitlines()]
    lines = [" ".join(line.split()) for line in lines if line]
    constants = [line for line in lines if "=" in line]
    fields = [line.replace("Header ", f"{header} ", 1) for line in lines if "=" not in line]
    text = "\n".join(constants + fields)

    def check(answer: str):
        return subprocess.run([PYTHON, "-m", "minros", "learn", "check", "5", "--dir", str(base),
                               answer], capture_output=True, text=True, timeout=60)

    wrong = check(hashlib.md5((text + "\n").encode()).hexdigest())
    assert wrong.returncode == 1 and "no newline at the end" in wrong.stdout
    right = check(hashlib.md5(text.encode()).hexdigest())
    assert right.returncode == 0 and right.stdout.startswith("Right"), right.stdout


def test_6_an_md5sum_mismatch(learner):
    me = learner(6)

    def refused(events):
        return any(e.get("ev") == "tcpros.header" and e.get("dir") == "out"
                   and any(k == "error" for k, _v in e.get("fields", [])) for e in events)

    me.traced_until("me.jsonl", [PYTHON, "-m", "minros", "topic", "pub", "-r", "1",
                                 "/greetings", "std_msgs/String", "data: hello"], refused,
                    "the refusal")
    shown = me.show(str(me.path("me.jsonl")), "--topic", "/greetings")
    asked = re.search(r"callerid=/old_listener\s+md5sum=([0-9a-f]{32})", shown).group(1)
    me.wrong_then_right([asked, "subscriber"], "error=", [asked, "publisher"])
    me.stop()


def test_7_latched_or_not(learner):
    me = learner(7)
    latched = me.facts["latched"]
    other = "/window" if latched == "/door" else "/door"
    # the latched topic's message arrives at once; the other echo waits and is stopped
    me.traced(f"me-{latched[1:]}.jsonl", "topic", "echo", "-n", "1", latched)
    me.traced_until(f"me-{other[1:]}.jsonl", [PYTHON, "-m", "minros", "topic", "echo", "-n",
                                             "1", other], _header_in(other), "the header")
    shown = me.show(*map(str, sorted(me.folder.glob("me-*.jsonl"))))
    found = re.search(r"latching=1\s+md5sum=\w+\s+message_definition=.*\s+topic=(/\w+)", shown)
    assert found.group(1) == latched
    me.wrong_then_right([other, "latching=1"], "latching= field", [latched, "latching=1"])
    me.stop()


def test_8_the_probe_and_the_persistent_call(learner):
    me = learner(8)
    done = me.run("trace", "-o", str(me.path("me.jsonl")), "--", PYTHON,
                  str(me.path("client.py")))
    assert done.returncode == 0 and "2 + 10 = 12" in done.stdout, done.stderr
    shown = me.show(str(me.path("me.jsonl")), "--service", "/add_two_ints", "--frames", "all")
    connections = len(re.findall(r"#\d+ TCP connection", shown))
    assert connections == 2 and "probe=1" in shown
    me.wrong_then_right([str(connections + 2), "probe=1"], "persistent=True keeps one",
                        [str(connections), "probe=1"])
    me.stop()


def test_9_nagle_and_tcp_nodelay(learner):
    me = learner(9)
    for name, extra in (("me-nagle.jsonl", []), ("me-nodelay.jsonl", ["--tcpnodelay"])):
        me.traced_until(name, [PYTHON, "-m", "minros", "topic", "hz", *extra, "/sensor"],
                        _frames_in("/sensor", 200), f"200 frames ({name})")
    shown = me.show(str(me.path("sensor.jsonl")), str(me.path("me-nodelay.jsonl")), "--topic",
                    "/sensor", "--frames", "0")
    assert "tcp_nodelay=1" in shown and "frames received" in shown
    out = me.wrong_then_right(["tcp_nodelay=0"], "Your second subscription", ["tcp_nodelay=1"])
    assert re.search(r"tcp_nodelay=0: \d+ frames: median", out)
    assert re.search(r"tcp_nodelay=1: \d+ frames: median", out)
    me.stop()


def test_10_the_master_restarts(learner):
    me = learner(10)
    pid = me.facts["master_pid"]
    os.kill(pid, signal.SIGTERM)  # kill PID, as the task says
    me.proc.read_until(f"master (pid {pid}) ended", 30)
    master2: Optional[Proc] = Proc([PYTHON, "-m", "minros", "trace", "-o",
                                    str(me.path("master2.jsonl")), "--", PYTHON, "-m", "minros",
                                    "core", "-p", str(me.facts["port"])], me.env)
    try:
        def registered(events: List[dict]) -> bool:
            methods = {(e.get("method"), (e.get("args") or [""])[0]) for e in events
                       if e.get("ev") == "xmlrpc.serve"}
            return {("registerPublisher", "/talker"),
                    ("registerSubscriber", "/listener")} <= methods

        wait_until(lambda: registered(_events(me.path("master2.jsonl"))), 30,
                   what="the nodes registering with the new master")
        shown = me.show(*map(str, sorted(me.folder.glob("*.jsonl"))), "--topic", "/chatter")
        assert shown.count('registerPublisher("/talker", "/chatter"') >= 2
        me.wrong_then_right(["requestTopic"], "Look at the calls the new master served",
                            ["registerPublisher", "registerSubscriber"])
    finally:
        master2.stop()
    me.stop()


def test_11_a_topic_across_two_masters_through_a_relay(learner):
    me = learner(11, "--via", "relay")
    assert me.facts["variant"] == "relay"
    assert me.env["ROS_MASTER_URI"] == me.facts["master_b"]
    me.traced("me.jsonl", "topic", "echo", "-n", "1", "/chatter")
    shown = me.show(str(me.path("me.jsonl")), "--topic", "/chatter")
    sender = re.findall(r"callerid=(/\w+)", shown)[1]  # the publisher's header, the second
    assert sender == "/relay"
    out = me.wrong_then_right(["/talker", "2"], "never talked", [sender, "2"])
    assert "Master A's trace has no call from your node" in out
    me.stop()


def _sockets(pid: int) -> List[tuple]:
    """The TCP sockets ``pid`` listens on and the UDP sockets it has bound, as (protocol,
    address, port), from /proc (the namespace's socket tables, matched by inode)."""
    inodes = set()
    for fd in os.listdir(f"/proc/{pid}/fd"):
        try:
            link = os.readlink(f"/proc/{pid}/fd/{fd}")
        except OSError:
            continue
        if link.startswith("socket:["):
            inodes.add(link[len("socket:["):-1])
    found = []
    for proto in ("tcp", "tcp6", "udp", "udp6"):
        lines = Path(f"/proc/{pid}/net/{proto}").read_text().splitlines()[1:]
        for cols in (line.split() for line in lines):
            if cols[9] not in inodes or (proto.startswith("tcp") and cols[3] != "0A"):
                continue  # not this process's, or a TCP socket that is not listening
            address, port = cols[1].split(":")
            raw = bytes.fromhex(address)
            if len(raw) == 4:
                host = socket.inet_ntop(socket.AF_INET, raw[::-1])
            else:
                host = socket.inet_ntop(socket.AF_INET6, b"".join(
                    raw[i:i + 4][::-1] for i in range(0, 16, 4)))
            found.append((proto, host, int(port, 16)))
    return found


def test_11_a_topic_across_two_masters_through_minros_zenoh(learner):
    require_zenoh()
    me = learner(11)  # the default where eclipse-zenoh is installed
    assert me.facts["variant"] == "zenoh" and "minros learn check 11 CALLERID KEY" in me.task
    assert f"listens on tcp/127.0.0.1:{me.facts['zenoh_port']}" in me.task
    # nothing reaches the LAN: the bridges listen on loopback only and scout no multicast
    for name in ("bridge_a", "bridge_b"):
        bound = _sockets(me.facts["pids"][name])
        assert bound and all(host == "127.0.0.1" and proto == "tcp"
                             for proto, host, _port in bound), (name, bound)
    assert ("tcp", "127.0.0.1", me.facts["zenoh_port"]) in _sockets(me.facts["pids"]["bridge_a"])
    assert not (me.folder / "bridge_a.jsonl").exists()  # untraced: the others show its calls
    me.traced("me.jsonl", "topic", "echo", "-n", "1", "/chatter")
    shown = me.show(*map(str, sorted(me.folder.glob("*.jsonl"))), "--topic", "/chatter")
    # master B's trace: the bridge registered /chatter there as a publisher
    assert re.search(r'/minros_zenoh -> /master +registerPublisher\("/minros_zenoh", '
                     r'"/chatter", "std_msgs/String"', shown), shown
    mine = me.show(str(me.path("me.jsonl")), "--topic", "/chatter")
    sender = re.findall(r"callerid=(/\w+)", mine)[1]  # the publisher's header, the second
    assert sender == "/minros_zenoh"
    keys = me.run("zenoh", "keys", "/chatter")  # asks master B and the bridge there
    assert keys.returncode == 0, keys.stderr
    key = keys.stdout.strip()
    assert key == "7374645f6d7367732f537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/*/chatter"
    code, out = me.check("/talker", key)
    assert code == 1 and "reached master B through the bridges" in out, out
    out = me.wrong_then_right([sender, "std_msgs/String"], "one part of the key", [sender, key])
    assert "Master B's trace shows /minros_zenoh's registerPublisher for /chatter" in out
    assert "no call from your node" in out
    me.stop()


def test_the_page_starts_exercise_11_through_minros_zenoh_and_stops_it(tmp_path):
    """The Learn view's server side (minros.web.learning) with the real runner: what a page's
    Start runs for exercise 11, checked and stopped as the page does it."""
    from minros.web.learning import LearnHub

    require_zenoh()
    home = tmp_path / "ros_home"
    (home / "log").mkdir(parents=True)
    hub = LearnHub(tmp_path / "learn")
    try:
        run = hub.start("page", 11)
        wait_until(lambda: hub.status("page")["state"] != "starting", 90, what="the start")
        status = hub.status("page")
        assert status["state"] == "running", status
        assert status["variant"] == "zenoh" and "key expression" in status["task"]
        assert [p["name"] for p in status["processes"]] == [
            "master", "master_b", "talker", "bridge_a", "bridge_b"]
        env = {k: v for k, v in os.environ.items()
               if not k.startswith(("ROS_", "MINROS_")) and k != "PYTHONPATH"}
        env.update(ROS_HOME=str(home), ROS_MASTER_URI=run.facts["master_b"],
                   ROS_HOSTNAME="localhost")
        echo = subprocess.run([PYTHON, "-m", "minros", "trace", "-o", run.facts["me"], "--",
                               PYTHON, "-m", "minros", "topic", "echo", "-n", "1", "/chatter"],
                              env=env, capture_output=True, text=True, timeout=60)
        assert echo.returncode == 0, echo.stderr
        key = "7374645f6d7367732f537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/*/chatter"
        verdict = hub.check(11, f"/minros_zenoh {key}")
        assert verdict["ok"], verdict
        pids = [p["pid"] for p in status["processes"]]
        hub.stop("page")
        wait_until(lambda: hub.status("page")["state"] == "stopped", 60, what="the stop")
        assert hub.status("page")["reason"] == "stopped from the page"
        assert not [pid for pid in pids if _alive(pid)], "the page's start left processes"
    finally:
        hub.close()


def test_without_eclipse_zenoh_the_zenoh_variant_is_refused_in_one_line(tmp_path):
    # as if the extra were not installed: the module cannot be found
    code = ("import sys; sys.modules['zenoh'] = None; from minros.cli.main import main; "
            "sys.argv[0] = 'minros'; sys.exit(main())")
    done = subprocess.run([PYTHON, "-c", code, "learn", "11", "--via", "zenoh", "--dir",
                           str(tmp_path)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
    assert "pip install minros[zenoh]" in done.stderr and "--via relay" in done.stderr
    assert not list(tmp_path.iterdir())


@pytest.mark.smoke
def test_a_process_that_fails_to_start_is_named_and_the_others_are_stopped(tmp_path):
    from minros.learn.model import Exercise, Process
    from minros.learn.session import LearnError, Runner

    broken = Exercise(
        99, "broken", "A broken exercise", 1, "nothing", task="", answer_form="",
        check=lambda attempt: None,
        variants={"": (Process("master", ("minros", "core", "-p", "{port}"), ready=("master",)),
                       Process("talker", ("minros.learn.actors", "no_such_role"),
                               ready=("registerPublisher", "/chatter")))})
    runner = Runner(broken, tmp_path)
    with pytest.raises(LearnError, match=r"talker ended \(status 2\) before it was ready: .*"
                                         r"invalid choice: 'no_such_role'"):
        runner.start()
    master = runner.procs["master"]
    assert master.poll() is not None  # stopped, not left behind
    assert json.loads((runner.folder / "state.json").read_text())["running"] is False
