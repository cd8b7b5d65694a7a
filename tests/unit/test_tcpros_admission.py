"""The TCPROS side of the admission policy: a node's inbound handshakes and the frames a
service server reads (minros.node, minros.wire.sockets), over loopback sockets. The node has one
inbound server: every handshake test runs over its TCP port and over its abstract Unix socket
(shared memory's), which take the same rules; a subscriber refused there falls back to TCPROS
at once."""

from __future__ import annotations

import socket
import struct
import threading
import time

import pytest

from minros.exceptions import TransportTerminated
from minros.master import Master
from minros.node import Node
from minros.transport import shm
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


#: the node's listening sockets: its TCP port, and its abstract Unix socket (shared memory)
LISTENERS = ["tcp", pytest.param("unix", marks=pytest.mark.skipif(
    not shm.supported(), reason="no shared memory on this system"))]


class Address:
    """Where a test connects: the node's TCP port or its Unix socket's abstract name."""

    def __init__(self, node: Node, kind: str) -> None:
        self.kind = kind
        self.node = node
        if kind == "tcp":
            self.address: object = ("127.0.0.1", node.tcpros_address()[1])
        else:
            self.address = "\0" + node.connections.shm_address()

    def connect(self, timeout: float = 5.0) -> socket.socket:
        if self.kind == "tcp":
            return socket.create_connection(self.address, timeout=timeout)  # type: ignore[arg-type]
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(timeout)
        sock.connect(self.address)
        return sock

    @property
    def admission(self) -> Admission:
        listener = self.node.tcpros_server.listener("TCPROS" if self.kind == "tcp" else "MINROSSHM")
        return listener.admission


def tcpros_node(master: Master, limits: Limits, kind: str = "tcp") -> tuple:
    node = Node(argv=["prog", f"__master:={master.uri}", "__hostname:=127.0.0.1"])
    node.init("tcpros_probe", args_key=("tcpros_probe",))
    node.add_publication(FakePublication("/chatter"))
    node.connections.limits = limits
    return node, Address(node, kind)


def handshake(address: Address, timeout: float = 2.0) -> dict:
    with address.connect(timeout) as s:
        s.sendall(tcpros.encode_header({"topic": "/chatter", "md5sum": MD5, "callerid": "/probe",
                                        "type": "std_msgs/String"}))
        return sockets.read_header(s)


@pytest.mark.parametrize("kind", LISTENERS)
def test_a_trickled_connection_header_cannot_extend_its_deadline(master, kind):
    node, port = tcpros_node(master, Limits(head_timeout=0.5), kind)
    try:
        s = port.connect()
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


@pytest.mark.parametrize("kind", LISTENERS)
def test_an_announced_header_holds_nothing_and_blocks_nobody(master, kind):
    node, port = tcpros_node(master, Limits(), kind)
    hostile = []
    try:
        for _ in range(20):
            s = port.connect()
            s.sendall(struct.pack("<I", 1 << 20) + b"ab")  # a 1 MiB header announced
            hostile.append(s)
        for _ in range(5):
            assert handshake(port) == SERVED
        assert port.admission.held() <= 20 * 6
    finally:
        for s in hostile:
            s.close()
        node.signal_shutdown("test over")


@pytest.mark.parametrize("kind", LISTENERS)
def test_a_full_tcpros_server_closes_its_slowest_handshakes(master, kind):
    node, port = tcpros_node(master, Limits(max_connections=10, peer_share=1.0), kind)
    tricklers = []
    try:
        for _ in range(15):
            s = port.connect()
            s.sendall(b"\x10")
            tricklers.append(s)
        for _ in range(5):
            assert handshake(port) == SERVED
        assert port.admission.evictions >= 5
        assert port.admission.live() <= 10
    finally:
        for s in tricklers:
            s.close()
        node.signal_shutdown("test over")


@pytest.mark.parametrize("kind", LISTENERS)
def test_silent_connections_keep_no_subscriber_off(master, kind):
    """The probe of issue 38 (item 2): 64 connections that say nothing, on the node's TCP port
    or its shared-memory socket, and a subscriber's handshake is still answered at once (the
    old shared-memory server took 64 handshakes at a time and closed every later one: nothing
    got through for 15 s); with a cap of 32 the silent ones are evicted from the peer holding
    most, the oldest first."""
    node, port = tcpros_node(master, Limits(max_connections=32), kind)
    silent = [port.connect() for _ in range(64)]
    try:
        start = time.monotonic()
        for _ in range(5):
            assert handshake(port, timeout=5.0) == SERVED
        assert time.monotonic() - start < 5.0
        assert port.admission.evictions >= 32 and port.admission.live() <= 32
    finally:
        for s in silent:
            s.close()
        node.signal_shutdown("test over")


@pytest.mark.skipif(not shm.supported(), reason="no shared memory on this system")
def test_a_subscriber_refused_on_the_shared_memory_socket_falls_back_to_tcpros_at_once(
        master, monkeypatch):
    """A refusal by the Unix socket's admission is a FallBack: the subscriber asks again with
    TCPROS at once (a retry would wait RETRY_FIRST, made far longer than the test's wait)."""
    from minros.client import subscription
    from minros.client.publication import Publication
    from minros.client.subscription import Subscription
    from std_msgs.msg import String

    monkeypatch.setattr(subscription, "RETRY_FIRST", 60.0)
    pub_node = Node(argv=["prog", f"__master:={master.uri}", "__hostname:=127.0.0.1"])
    pub_node.init("refusing_talker", args_key=("refusing_talker",))
    sub_node = Node(argv=["prog", f"__master:={master.uri}", "__hostname:=127.0.0.1"])
    sub_node.init("refused_listener", args_key=("refused_listener",))
    try:
        pub = Publication(pub_node, "/chatter", "/chatter", String)
        pub.queue_size = 10
        pub_node.add_publication(pub)
        unix = Address(pub_node, "unix").admission

        def refuse(*args, **kwargs):
            raise Refused("the shared-memory socket is full: try again")

        monkeypatch.setattr(unix, "admit", refuse)
        got = threading.Event()
        sub = Subscription(sub_node, "/chatter", "/chatter", String)
        sub.add_callback(lambda msg: got.set(), None)
        sub_node.add_subscription(sub)
        deadline = time.monotonic() + 10.0
        while not got.is_set() and time.monotonic() < deadline:
            pub.publish(String("hello"))
            got.wait(0.05)
        assert got.is_set(), "the subscriber never got a message"
        assert [c.protocol for c in sub.connections] == ["TCPROS"]
        assert [c.transport_type for c in pub.connections] == ["TCPROS"]
    finally:
        sub_node.signal_shutdown("test over")
        pub_node.signal_shutdown("test over")


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

    def dispatch(stream, header, conn, listener):
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
