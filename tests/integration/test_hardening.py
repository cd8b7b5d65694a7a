"""The three defects of issue 18, against a real ``minros master`` process: a client on the same
host must not be able to stall everybody else's calls or fill the disk.

1. requests announcing 64 MiB bodies and then sending nothing (or a byte now and then);
2. more connections than the server's cap, each trickling its headers a byte at a time;
3. ``setParam`` calls with a 1 MiB caller_id, each logged to master.log.

Each attack test measures the master's answer time to ``getSystemState`` probes during the
attack and prints it (``-s`` shows it); ``benchmarks/master.py`` sets the same figures beside
Debian's rosmaster.
"""

from __future__ import annotations

import socket
import statistics
import threading
import time
import xmlrpc.client
from pathlib import Path

import pytest

from support import PYTHON, Proc, free_port, ros_env, wait_for_master, wait_until

HUGE_BODY = b"POST / HTTP/1.1\r\nContent-Type: text/xml\r\nContent-Length: 67108864\r\n\r\n<?xml"


def probe_times(port: int, count: int, timeout: float = 2.0) -> list:
    """Answer times of ``count`` getSystemState calls, each on a fresh connection (as a
    starting node makes them); an unanswered probe fails the test."""
    times = []
    for _ in range(count):
        start = time.perf_counter()
        with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
            body = xmlrpc.client.dumps(("/probe",), "getSystemState").encode()
            s.sendall(b"POST / HTTP/1.1\r\nContent-Length: %d\r\n\r\n%s" % (len(body), body))
            reply = b""
            while b"</methodResponse>" not in reply:
                chunk = s.recv(65536)
                assert chunk, "the master closed the probe's connection"
                reply += chunk
        assert b"current system state" in reply
        times.append(time.perf_counter() - start)
    return times


def report(what: str, times: list) -> None:
    print(f"\n{what}: {len(times)} probes answered, median {statistics.median(times) * 1e3:.2f} ms, "
          f"max {max(times) * 1e3:.2f} ms")


class Trickler:
    """Sends one byte to each of ``conns`` every ``interval`` seconds until stopped."""

    def __init__(self, conns: list, data: bytes, interval: float) -> None:
        self.conns = conns
        self.data = data
        self.interval = interval
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        pos = 0
        while not self.stop.wait(self.interval):
            byte = self.data[pos % len(self.data):pos % len(self.data) + 1]
            pos += 1
            for s in self.conns:
                try:
                    s.send(byte)
                except OSError:
                    pass

    def close(self) -> None:
        self.stop.set()
        self.thread.join(5)
        for s in self.conns:
            s.close()


@pytest.mark.smoke
def test_announced_huge_bodies_do_not_stall_the_master(minros_master):
    """Defect 1: four requests announcing 64 MiB, then a byte a second: every other call to
    the master waited (0 of 3 getSystemState answered in 5 s; rosmaster 12 of 12)."""
    hostile = []
    for _ in range(4):
        s = socket.create_connection(("127.0.0.1", minros_master), timeout=5)
        s.sendall(HUGE_BODY)
        hostile.append(s)
    trickler = Trickler(hostile, b"<", 1.0)
    try:
        time.sleep(0.2)  # the requests are in; nothing here waits on them
        times = probe_times(minros_master, 12)
        report("during 4 x 64 MiB announced bodies", times)
        assert max(times) < 2.0
    finally:
        trickler.close()


def test_a_node_started_during_the_attack_on_its_peer_connects(minros_master, ros_home, tmp_path):
    """Defect 1 on a node's port: with the listener's XML-RPC port under the same attack, a
    talker started during it must still reach the listener (it never did)."""
    env = ros_env(minros_master, ros_home)
    listener = Proc([PYTHON, "-c", LISTENER], env)
    talker = None
    hostile = []
    try:
        listener.read_until("listening", 20)
        proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{minros_master}/")
        code, _, uri = proxy.lookupNode("/test", "/listener")
        assert code == 1
        host_port = uri.split("//", 1)[1].rstrip("/")
        port = int(host_port.rsplit(":", 1)[1])
        for _ in range(4):
            s = socket.create_connection(("127.0.0.1", port), timeout=5)
            s.sendall(HUGE_BODY)
            hostile.append(s)
        talker = Proc([PYTHON, "-c", TALKER], env)
        listener.read_until("I heard", 20)
    finally:
        for s in hostile:
            s.close()
        if talker is not None:
            talker.stop()
        listener.stop()


def test_a_full_master_of_trickling_connections_still_answers(minros_master):
    """Defect 2: 1100 connections trickling their headers a byte at a time held the master's
    1024 connections (0 of 3 probes answered; rosmaster 17 of 17 in 5 ms)."""
    conns = []
    for _ in range(1100):
        s = socket.create_connection(("127.0.0.1", minros_master), timeout=5)
        s.setblocking(False)
        conns.append(s)
    trickler = Trickler(conns, b"POST / HTTP/1.1\r\nUser-Agent: " + b"slow" * 1000, 0.2)
    try:
        time.sleep(1.0)  # every connection has started its head
        times = probe_times(minros_master, 17)
        report("with 1100 trickling connections", times)
        assert max(times) < 2.0
    finally:
        trickler.close()


def test_master_log_is_bounded_against_huge_caller_ids(ros_home):
    """Defect 3: every setParam is logged with its caller_id, which a client chooses: 300
    calls with a 1 MiB caller_id wrote a 315 MB master.log in 2.5 s."""
    port = free_port()
    log = ros_home / "log" / "master.log"
    proc = Proc([PYTHON, "-m", "minros.master", "-p", str(port), f"__log:={log}"],
                ros_env(port, ros_home))
    try:
        wait_for_master(port)
        proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")
        caller = "/" + "x" * (1 << 20)
        for i in range(40):
            assert proxy.setParam(caller, f"/p{i}", i)[0] == 1
        wait_until(lambda: "/p39" in log.read_text(errors="replace"), 10, what="the last line")
    finally:
        proc.stop()
    total = sum(p.stat().st_size for p in Path(log.parent).glob("master.log*"))
    assert total < 1 << 20, f"40 calls wrote {total} bytes of master.log"
    lines = log.read_text().splitlines()
    assert any("+PARAM [/p39] by /xxx" in line and line.endswith("characters]") for line in lines)


LISTENER = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("listener")
rospy.Subscriber("chatter", String, lambda m: print("I heard", m.data, flush=True))
print("listening", flush=True)
rospy.spin()
'''

TALKER = r'''
import rospy
from std_msgs.msg import String
rospy.init_node("talker")
pub = rospy.Publisher("chatter", String, queue_size=10)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    pub.publish(String("hello"))
    rate.sleep()
'''


def test_minros_web_full_of_silent_connections_still_serves(minros_core, ros_home):
    """The same rules in ``minros web``: past its 512 connections the oldest ones that have not
    sent their request are closed, so a browser connecting now is served."""
    import json

    from websockets.sync.client import connect

    web_port = free_port()
    web = Proc([PYTHON, "-m", "minros", "web", "--port", str(web_port)],
               ros_env(minros_core, ros_home))
    silent = []
    try:
        web.read_until("ws://", 30)
        for _ in range(600):
            silent.append(socket.create_connection(("127.0.0.1", web_port), timeout=5))
        start = time.perf_counter()
        with connect(f"ws://127.0.0.1:{web_port}", open_timeout=5) as ws:
            ws.send(json.dumps({"op": "call_service", "service": "/rosapi/topics", "id": "t"}))
            reply = json.loads(ws.recv(timeout=10))
        print(f"\nminros web with 600 silent connections: answered in "
              f"{(time.perf_counter() - start) * 1e3:.1f} ms")
        assert reply["op"] == "service_response" and reply["result"] is True
        closed = 0
        deadline = time.monotonic() + 2.0  # well before websockets' 10 s handshake timeout
        for s in silent[:88]:  # the oldest ones made room
            s.settimeout(max(0.01, deadline - time.monotonic()))
            try:
                closed += s.recv(1) == b""
            except socket.timeout:
                pass  # still open
            except OSError:  # reset
                closed += 1
        assert closed >= 80
    finally:
        for s in silent:
            s.close()
        web.stop()
