"""The TCPROS side of the admission policy: a node's inbound handshakes and the frames a
service server reads (minros.node, minros.wire.sockets), over loopback sockets."""

from __future__ import annotations

import socket
import struct
import threading
import time

import pytest

from minros.exceptions import TransportTerminated
from minros.master import Master
from minros.node import Node
from minros.wire import sockets, tcpros
from minros.wire.admission import Admission, Connection, Limits, Refused

MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"


SERVED = {"error": "Internal error processing topic [/chatter]"}


class FakePublication:
    """A closed publication: the handshake is served, and refused."""

    type = "std_msgs/String"
    md5sum = MD5
    closed = True
    queue_size = None
    tcp_nodelay = False

    def __init__(self, name: str) -> None:
        self.resolved_name = name

    def header_fields(self):
        return {"topic": self.resolved_name, "type": self.type, "md5sum": MD5, "callerid": "/p"}

    def add_connection(self, transport):
        raise AssertionError("a closed publication takes no connection")

    def remove_connection(self, transport):
        pass

    def get_stats(self):
        return [self.resolved_name, 0, []]

    def get_stats_info(self):
        return []

    def close(self):
        pass


@pytest.fixture
def master():
    m = Master(port=0, host="127.0.0.1", hostname="127.0.0.1").start()
    yield m
    m.stop()


def tcpros_node(master: Master, limits: Limits) -> tuple:
    node = Node(argv=["prog", f"__master:={master.uri}", "__hostname:=127.0.0.1"])
    node.init("tcpros_probe", args_key=("tcpros_probe",))
    node.add_publication(FakePublication("/chatter"))
    node.connections.limits = limits
    return node, node.tcpros_address()[1]


def handshake(port: int, timeout: float = 2.0) -> dict:
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(tcpros.encode_header({"topic": "/chatter", "md5sum": MD5, "callerid": "/probe",
                                        "type": "std_msgs/String"}))
        return sockets.read_header(s)


def test_a_trickled_connection_header_cannot_extend_its_deadline(master):
    node, port = tcpros_node(master, Limits(head_timeout=0.5))
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=5)
        start = time.monotonic()
        s.settimeout(0.1)
        closed = False
        for byte in struct.pack("<I", 200) + b"x" * 200:
            try:
                s.send(bytes([byte]))
                closed = s.recv(10) == b""
            except socket.timeout:
                continue
            except OSError:
                closed = True
            if closed:
                break
        assert closed and 0.4 < time.monotonic() - start < 3.0
        s.close()
        assert handshake(port) == SERVED
    finally:
        node.signal_shutdown("test over")


def test_an_announced_header_holds_nothing_and_blocks_nobody(master):
    node, port = tcpros_node(master, Limits())
    hostile = []
    try:
        for _ in range(20):
            s = socket.create_connection(("127.0.0.1", port), timeout=5)
            s.sendall(struct.pack("<I", 1 << 20) + b"ab")  # a 1 MiB header announced
            hostile.append(s)
        for _ in range(5):
            assert handshake(port) == SERVED
        assert node.tcpros_server.admission.held() <= 20 * 6
    finally:
        for s in hostile:
            s.close()
        node.signal_shutdown("test over")


def test_a_full_tcpros_server_closes_its_slowest_handshakes(master):
    node, port = tcpros_node(master, Limits(max_connections=10, peer_share=1.0))
    tricklers = []
    try:
        for _ in range(15):
            s = socket.create_connection(("127.0.0.1", port), timeout=5)
            s.sendall(b"\x10")
            tricklers.append(s)
        for _ in range(5):
            assert handshake(port) == SERVED
        assert node.tcpros_server.admission.evictions >= 5
        assert node.tcpros_server.admission.live() <= 10
    finally:
        for s in tricklers:
            s.close()
        node.signal_shutdown("test over")


# --------------------------------------------------------------------------- guarded frames


def guarded(limits: Limits) -> tuple:
    adm = Admission(limits)
    ours, theirs = socket.socketpair()
    adm.admit(1, "127.0.0.1")
    evicted = []
    conn = Connection(adm, 1, evicted.extend)
    ours.settimeout(1.0)
    return adm, conn, ours, theirs, evicted


def test_guarded_frames_are_charged_and_a_trickled_one_is_cut_at_its_deadline():
    adm, conn, ours, theirs, _ = guarded(Limits(head_timeout=0.3, min_rate=1000.0))
    with ours, theirs:
        source = sockets.FrameSource(ours, tcpros.FrameReader(), guard=conn)
        theirs.sendall(tcpros.encode_frame(b"hello"))
        assert source.next() == b"hello" and adm.held() == 9
        conn.release()
        start = time.monotonic()
        theirs.sendall(struct.pack("<I", 300) + b"a")  # due 0.3 + 0.3 s after its first byte

        def trickle() -> None:
            for _ in range(40):
                time.sleep(0.05)
                try:
                    theirs.send(b"b")
                except OSError:
                    return

        threading.Thread(target=trickle, daemon=True).start()
        with pytest.raises(TransportTerminated, match="the request did not arrive within the deadline"):
            source.next()
        assert 0.5 < time.monotonic() - start < 1.5


def test_a_one_shot_client_must_send_its_request_in_time():
    _, conn, ours, theirs, _ = guarded(Limits())
    with ours, theirs:
        source = sockets.FrameSource(ours, tcpros.FrameReader(), guard=conn)
        start = time.monotonic()
        with pytest.raises(TransportTerminated, match="no request arrived within the deadline"):
            source.next(wait_until=time.monotonic() + 0.3)
        assert 0.25 < time.monotonic() - start < 1.5


def test_guarded_frames_over_the_budget_are_refused():
    _, conn, ours, theirs, _ = guarded(Limits(budget=1000, peer_share=1.0))
    with ours, theirs:
        source = sockets.FrameSource(ours, tcpros.FrameReader(first_chunk=64), guard=conn)
        theirs.sendall(struct.pack("<I", 5000) + b"x" * 2000)
        with pytest.raises(Refused, match="busy with large requests"):
            source.next()


def test_read_header_keeps_only_what_arrived_and_honours_its_deadline():
    ours, theirs = socket.socketpair()
    with ours, theirs:
        charged = []
        theirs.sendall(struct.pack("<I", 1 << 20) + b"k=v")
        start = time.monotonic()
        with pytest.raises(tcpros.HeaderError, match="timed out"):
            sockets.read_header(ours, deadline=time.monotonic() + 0.2, charge=charged.append)
        assert sum(charged) == 7 and time.monotonic() - start < 1.5


def test_closing_the_server_wakes_a_connection_blocked_in_recv():
    """A service connection waits for its next request in a blocking recv (no timeout): the
    server's close() at node shutdown shuts it down, so its thread ends at once."""
    from minros.node.tcpros_server import TCPROSServer

    waiting = threading.Event()
    ended = threading.Event()
    got: list = []

    def dispatch(stream, header, conn):
        stream.settimeout(None)
        waiting.set()
        got.append(stream.recv(10))  # what a persistent connection between requests does
        ended.set()
        return None

    server = TCPROSServer(dispatch, lambda: False)
    server.start("127.0.0.1", 0)
    client = socket.create_connection(("127.0.0.1", server.port), timeout=5)
    try:
        client.sendall(tcpros.encode_header({"service": "/s", "md5sum": "*", "callerid": "/c"}))
        assert waiting.wait(5)
        assert not ended.wait(0.3)  # blocked: nothing wakes it but the close
        server.close()
        assert ended.wait(2.0) and got == [b""]
    finally:
        client.close()
        server.close()
