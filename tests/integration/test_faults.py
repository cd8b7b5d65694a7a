"""Faults under a running graph, each bounded in time (issue 18): the master SIGKILLed and
restarted, a publisher SIGKILLed mid-frame, a subscriber that never reads (queue_size=10 and
None), a service server that never answers, roslaunch SIGKILLed, Ctrl-C of everything.

A talker/listener pair counts its messages through each fault: the talker prints every number
it publishes, the listener every number it receives, and each test prints what was sent, what
arrived and what was lost (``-s`` shows it). Nothing may be lost that ROS itself would not
lose: an established connection outlives the master; a queued publisher drops only for the
subscriber that does not read; a synchronous one (queue_size=None) waits for it, as rospy does.
"""

from __future__ import annotations

import os
import re
import signal
import socket
import sys
import time
import xmlrpc.client
from pathlib import Path
from typing import List

import pytest

from support import PYTHON, Proc, free_port, ros_env, wait_for_master, wait_until

pytestmark = pytest.mark.timeout(120)
BIN = Path(sys.executable).parent

COUNT_TALKER = r'''
import sys
import rospy
from std_msgs.msg import String
hz, queue, size = float(sys.argv[1]), sys.argv[2], int(sys.argv[3])
rospy.init_node("count_talker")
pub = rospy.Publisher("count", String, queue_size=None if queue == "none" else int(queue))
pad = "x" * size
rate = rospy.Rate(hz)
i = 0
while not rospy.is_shutdown():
    pub.publish(String("%d %s" % (i, pad)))
    print("sent", i, flush=True)
    i += 1
    try:
        rate.sleep()
    except rospy.ROSInterruptException:
        break
'''

COUNT_LISTENER = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("count_listener", anonymous=True)
rospy.Subscriber("count", String, lambda m: print("got", m.data.split(" ", 1)[0], flush=True))
print("listening", flush=True)
rospy.spin()
'''


class Counted:
    """A node process whose output is kept whole: what read_until() consumed and the rest."""

    def __init__(self, argv: List[str], env: dict) -> None:
        self.proc = Proc(argv, env)
        self.text = ""
        self.stopped = False

    def wait_for(self, needle: str, timeout: float = 20) -> None:
        self.text += self.proc.read_until(needle, timeout)

    def wait_count(self, word: str, count: int, timeout: float = 20) -> None:
        """Until ``count`` more '<word> N' lines arrived."""
        for _ in range(count):
            self.wait_for(f"{word} ", timeout)

    def drain(self) -> None:
        """Take in the lines the process has printed so far, without waiting."""
        import select

        fd = self.proc.popen.stdout.fileno()
        while select.select([fd], [], [], 0)[0]:
            chunk = os.read(fd, 65536)
            if not chunk:
                break
            self.proc._pending += chunk
        done, _, rest = self.proc._pending.rpartition(b"\n")
        if done:
            self.text += done.decode("utf-8", "replace") + "\n"
            self.proc._pending = rest

    def stop(self, sig: int | None = None) -> str:
        if self.stopped:
            return self.text
        self.stopped = True
        if sig is not None and self.proc.alive():
            os.killpg(self.proc.pid, sig)
            try:
                self.proc.popen.wait(10)
            except Exception:  # noqa: BLE001 - Proc.stop escalates
                pass
        self.text += self.proc.stop()
        return self.text

    def numbers(self, word: str) -> List[int]:
        return [int(n) for n in re.findall(rf"^{word} (\d+)$", self.text, re.M)]


def finish(pub: Counted, subs: List[Counted], others: List[Counted] = ()) -> None:
    """Stop the talker first, let its listeners take in what it sent last, then stop them."""
    pub.stop(signal.SIGINT)
    sent = pub.numbers("sent")
    for sub in subs:
        if sent and sub.proc.alive():
            try:
                sub.wait_for(f"got {sent[-1]}\n", 5)
            except AssertionError:
                pass  # counted as lost below
        sub.stop(signal.SIGINT)
    for node in others:
        node.stop(signal.SIGINT)


def lost(sent: List[int], got: List[int]) -> List[int]:
    """What the listener should have had and did not: every number the talker sent from the
    first one the listener received (the ones before it were sent before it connected)."""
    if not got:
        return sent
    seen = set(got)
    return [n for n in sent if n >= got[0] and n not in seen]


def report(fault: str, sent: List[int], got: List[int], **extra: object) -> List[int]:
    missing = lost(sent, got)
    details = "".join(f", {k} {v}" for k, v in extra.items())
    print(f"\n[{fault}] talker sent {len(sent)}, listener received {len(got)}, "
          f"lost {len(missing)}{details}")
    return missing


def start_core(port: int, home: Path) -> Proc:
    core = Proc([PYTHON, "-m", "minros", "core", "-p", str(port)], ros_env(port, home))
    wait_for_master(port)
    return core


def talker(port: int, home: Path, hz: float = 50, queue: str = "10", size: int = 10) -> Counted:
    return Counted([PYTHON, "-c", COUNT_TALKER, str(hz), queue, str(size)], ros_env(port, home))


def listener(port: int, home: Path) -> Counted:
    node = Counted([PYTHON, "-c", COUNT_LISTENER], ros_env(port, home))
    node.wait_for("listening")
    return node


def node_uri(port: int, name: str) -> str:
    code, _, uri = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/").lookupNode("/test", name)
    assert code == 1, f"{name} is not registered"
    return uri


def publishers_of(port: int, topic: str) -> List[str]:
    state = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/").getSystemState("/test")[2]
    return next((nodes for name, nodes in state[0] if name == topic), [])


# --------------------------------------------------------------------------- the master


def test_master_sigkilled_and_restarted_under_a_running_graph(ros_home):
    port = free_port()
    core = start_core(port, ros_home)
    nodes: List[Counted] = []
    try:
        sub = listener(port, ros_home)
        pub = talker(port, ros_home)
        nodes += [sub, pub]
        sub.wait_count("got", 20)
        os.kill(core.pid, signal.SIGKILL)  # the master alone, as a crash would
        core.popen.wait(10)
        sub.wait_count("got", 50)  # the established connection goes on without a master
        core = start_core(port, ros_home)  # a fresh master knows nothing ...
        wait_until(lambda: publishers_of(port, "/count") == ["/count_talker"], 15,
                   what="the talker registered again")  # ... until the nodes register again
        late = listener(port, ros_home)  # a new node finds the talker through the new master
        nodes.append(late)
        late.wait_count("got", 10)
        sub.wait_count("got", 10)
        finish(pub, [sub, late])
    finally:
        for node in nodes:
            node.stop(signal.SIGINT)
        core.stop()
    sent, got = pub.numbers("sent"), sub.numbers("got")
    assert not report("master SIGKILL + restart", sent, got, **{"late listener": len(late.numbers("got"))})
    assert late.numbers("got")


# --------------------------------------------------------------------------- a publisher

RAW_PUBLISHER = r'''
import os, socket, struct, sys, threading, time, xmlrpc.client
from xmlrpc.server import SimpleXMLRPCServer
# A publisher of /count written with the standard library only, so that it can stop in the
# middle of a frame on purpose: five whole messages, then half of the sixth.
master = sys.argv[1]
tcpros = socket.create_server(("127.0.0.1", 0))
rpc = SimpleXMLRPCServer(("127.0.0.1", 0), logRequests=False)
rpc.register_function(lambda c, t, p: [1, "", ["TCPROS", "127.0.0.1", tcpros.getsockname()[1]]],
                      "requestTopic")
rpc.register_function(lambda c: [1, "", os.getpid()], "getPid")
rpc.register_function(lambda c, t, p: [1, "", 0], "publisherUpdate")
threading.Thread(target=rpc.serve_forever, daemon=True).start()
uri = "http://127.0.0.1:%d/" % rpc.server_address[1]
xmlrpc.client.ServerProxy(master).registerPublisher("/raw_talker", "/count", "std_msgs/String", uri)
conn, _ = tcpros.accept()
def exact(n):
    data = b""
    while len(data) < n:
        data += conn.recv(n - len(data))
    return data
exact(struct.unpack("<I", exact(4))[0])  # the subscriber's header
fields = {"topic": "/count", "type": "std_msgs/String", "md5sum": "992ce8a1687cec8c8bd883ec73ca41d1",
          "callerid": "/raw_talker", "latching": "0", "message_definition": "string data"}
items = [("%s=%s" % kv).encode() for kv in sorted(fields.items())]
body = b"".join(struct.pack("<I", len(i)) + i for i in items)
conn.sendall(struct.pack("<I", len(body)) + body)
def frame(text):
    data = text.encode()
    return struct.pack("<II", len(data) + 4, len(data)) + data
for i in range(1000, 1005):
    conn.sendall(frame("%d pad" % i))
    print("sent", i, flush=True)
half = frame("1005 pad")
conn.sendall(half[:len(half) // 2])
print("mid-frame", flush=True)
time.sleep(60)
'''


def test_publisher_sigkilled_mid_frame(ros_home):
    port = free_port()
    core = start_core(port, ros_home)
    nodes: List[Counted] = []
    try:
        sub = listener(port, ros_home)
        raw = Counted([PYTHON, "-c", RAW_PUBLISHER, f"http://127.0.0.1:{port}/"],
                      ros_env(port, ros_home))
        nodes += [sub, raw]
        raw.wait_for("mid-frame")
        sub.wait_count("got", 5)
        os.killpg(raw.proc.pid, signal.SIGKILL)
        raw.stop()
        pub = talker(port, ros_home)  # a real talker afterwards: the listener carries on
        nodes.append(pub)
        sub.wait_count("got", 20)
        assert sub.proc.alive()
        finish(pub, [sub])
    finally:
        for node in nodes:
            node.stop(signal.SIGINT)
        core.stop()
    got = sub.numbers("got")
    assert got[:5] == [1000, 1001, 1002, 1003, 1004]  # the whole ones, and not the cut one
    assert 1005 not in got and "Traceback" not in sub.text
    assert not report("publisher SIGKILL mid-frame", raw.numbers("sent"), got[:5])
    assert not report("... then a new talker", pub.numbers("sent"), got[5:])


# --------------------------------------------------------------------------- a subscriber


def never_reading_subscriber(port: int) -> socket.socket:
    """A subscriber of /count that completes its handshake with the talker and never reads."""
    from minros.wire import sockets, tcpros

    uri = node_uri(port, "/count_talker")
    code, _, (_, host, tcp_port) = xmlrpc.client.ServerProxy(uri).requestTopic(
        "/stuck", "/count", [["TCPROS"]])
    assert code == 1
    sock = socket.socket()
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # small: fills at once
    sock.settimeout(5)
    sock.connect((host, tcp_port))
    sock.sendall(tcpros.encode_header({"topic": "/count", "md5sum": "*", "callerid": "/stuck",
                                       "type": "std_msgs/String"}))
    assert "error" not in sockets.read_header(sock)
    return sock


@pytest.mark.parametrize("queue", ["10", "none"])
def test_a_subscriber_that_never_reads(ros_home, queue):
    port = free_port()
    core = start_core(port, ros_home)
    nodes: List[Counted] = []
    try:
        sub = listener(port, ros_home)
        pub = talker(port, ros_home, hz=100, queue=queue, size=64 * 1024)  # 6.4 MB/s
        nodes += [sub, pub]
        sub.wait_count("got", 10)
        stuck = never_reading_subscriber(port)
        sub.drain()
        before = len(sub.numbers("got"))
        time.sleep(3.0)  # the stuck subscriber's buffers fill within a second
        sub.drain()
        during = len(sub.numbers("got")) - before
        stuck.close()  # the stuck subscriber goes away
        sub.wait_count("got", 20)
        finish(pub, [sub])
    finally:
        for node in nodes:
            node.stop(signal.SIGINT)
        core.stop()
    sent, got = pub.numbers("sent"), sub.numbers("got")
    assert not report(f"subscriber never reads, queue_size={queue}", sent, got,
                      **{"received while it was connected (3 s)": during})
    if queue == "10":
        assert during >= 150  # a queued publisher goes on for the others (100 Hz nominal)
    else:
        # a synchronous publisher waits for every subscriber, as rospy's does: the others
        # get nothing more until the stuck one goes away, and then every message
        assert during < 150


# --------------------------------------------------------------------------- a service


STUCK_SERVER = r'''
import time
import rospy
from std_srvs.srv import Trigger, TriggerResponse
rospy.init_node("stuck_server")
rospy.Service("stuck", Trigger, lambda req: time.sleep(3600))
rospy.Service("ok", Trigger, lambda req: TriggerResponse(True, "fine"))
print("serving", flush=True)
rospy.spin()
'''

# A caller started from a shell's background job inherits SIGINT ignored (POSIX), and Python
# then leaves it ignored: the caller restores Python's own handler, as at a terminal.
CALLER = r'''
import signal
import sys
signal.signal(signal.SIGINT, signal.default_int_handler)
import rospy
from std_srvs.srv import Trigger
print("calling", flush=True)
try:
    print("answer", rospy.ServiceProxy(sys.argv[1], Trigger)().message, flush=True)
except rospy.ServiceException as exc:
    print("failed:", exc, flush=True)
'''


def test_a_service_server_that_never_answers(ros_home):
    port = free_port()
    core = start_core(port, ros_home)
    env = ros_env(port, ros_home)
    nodes: List[Counted] = []
    try:
        sub = listener(port, ros_home)
        pub = talker(port, ros_home)
        server = Counted([PYTHON, "-c", STUCK_SERVER], env)
        nodes += [sub, pub, server]
        server.wait_for("serving")
        stuck = [Counted([PYTHON, "-c", CALLER, "/stuck"], env) for _ in range(3)]
        nodes += stuck
        for caller in stuck:
            caller.wait_for("calling")
        sub.wait_count("got", 50)  # the graph goes on meanwhile
        ok = Counted([PYTHON, "-c", CALLER, "/ok"], env)  # and the node's other services answer
        nodes.append(ok)
        ok.wait_for("answer fine", 20)
        assert all(caller.proc.alive() for caller in stuck)  # still waiting, as with rospy
        os.killpg(stuck[0].proc.pid, signal.SIGINT)  # a waiting caller can be interrupted
        stuck[0].proc.popen.wait(10)
        os.killpg(server.proc.pid, signal.SIGKILL)  # the server dies: the others learn it
        for caller in stuck[1:]:
            caller.wait_for("failed: transport error completing service call", 15)
        sub.wait_count("got", 10)
        finish(pub, [sub], [server, ok, *stuck])
    finally:
        for node in nodes:
            node.stop(signal.SIGINT)
        core.stop()
    assert not report("service server never answers", pub.numbers("sent"), sub.numbers("got"),
                      **{"callers released": 2})


# --------------------------------------------------------------------------- roslaunch and Ctrl-C

LAUNCH = """<launch>
  <node pkg="rospy_tutorials" type="talker.py" name="talker" output="screen"/>
  <node pkg="rospy_tutorials" type="listener.py" name="listener" output="screen"/>
</launch>
"""

CHATTER_COUNTER = r'''
import itertools
import rospy
from std_msgs.msg import String
rospy.init_node("chatter_counter", anonymous=True)
count = itertools.count(1)
rospy.Subscriber("chatter", String, lambda m: print("got", next(count), flush=True))
print("listening", flush=True)
rospy.spin()
'''


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except OSError:
        return False


def test_roslaunch_sigkilled_leaves_no_orphans(ros_home, tmp_path):
    port = free_port()
    core = start_core(port, ros_home)
    launch_file = tmp_path / "pair.launch"
    launch_file.write_text(LAUNCH)
    launch = Counted([str(BIN / "roslaunch"), str(launch_file)], ros_env(port, ros_home))
    counter = None
    try:
        launch.wait_for("I heard", 30)
        pids = [int(p) for p in re.findall(r"started with pid \[(\d+)\]", launch.text)]
        assert len(pids) == 2
        counter = Counted([PYTHON, "-c", CHATTER_COUNTER], ros_env(port, ros_home))
        counter.wait_count("got", 5)
        os.kill(launch.proc.pid, signal.SIGKILL)  # roslaunch alone, no chance to clean up
        wait_until(lambda: not any(_alive(p) for p in pids), 20, what="its nodes gone")
        counter.drain()
        counted = len(counter.numbers("got"))
        time.sleep(1.0)  # the talker published at 10 Hz: nothing more comes
        counter.drain()
        assert len(counter.numbers("got")) == counted >= 5
    finally:
        launch.stop()
        if counter is not None:
            counter.stop()
        core.stop()
    print(f"\n[roslaunch SIGKILL] a listener counted {counted} talker messages, none after "
          f"roslaunch died; nodes left behind: 0 of {len(pids)}")


def test_ctrl_c_of_everything(ros_home, tmp_path):
    port = free_port()
    env = ros_env(port, ros_home)
    core = start_core(port, ros_home)
    launch_file = tmp_path / "pair.launch"
    launch_file.write_text(LAUNCH)
    launch = Counted([str(BIN / "roslaunch"), str(launch_file)], env)
    sub = listener(port, ros_home)
    pub = talker(port, ros_home)
    everything = [launch, sub, pub]
    try:
        launch.wait_for("I heard", 30)
        sub.wait_count("got", 30)
        start = time.monotonic()
        # one Ctrl-C for all at once; the talker's first, as when it is the last to react:
        # under load the talker, signalled last, went on publishing for 60 ms to a
        # listener that had stopped already
        for proc in [pub.proc, core, launch.proc, sub.proc]:
            os.killpg(proc.pid, signal.SIGINT)
        codes = [p.popen.wait(20) for p in [core, *(n.proc for n in everything)]]
        took = time.monotonic() - start
    finally:
        for node in everything:
            node.stop()
        core.stop()
    assert codes == [0, 0, 0, 0], codes
    for node in everything:
        assert "Traceback" not in node.text, node.text
    missing = report("Ctrl-C of everything", pub.numbers("sent"), sub.numbers("got"),
                     **{"all exited in": f"{took:.1f} s"})
    # the talker may publish its last message as the listener is already stopping
    assert len(missing) <= 1
