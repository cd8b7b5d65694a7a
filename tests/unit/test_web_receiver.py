"""The web node's Receiver (minros.web.receiver) against hand-made publishers on real
sockets: one receive thread for every subscription, the handshake checks, reconnection while
the master lists a publisher, giving up on one that refuses."""

from __future__ import annotations

import queue
import socket
import struct
import threading
import time

import pytest

from minros.msgs import get_message_class
from minros.transport.tcpros_pubsub import TCPROSHandler
from minros.web.receiver import Receiver
from minros.web.state import raw_class
from minros.wire import sockets, tcpros
from minros.wire.xmlrpc import XmlRpcServer

String = get_message_class("std_msgs/String")
RawString = raw_class(String._type, String._md5sum, String._full_text)
TIMEOUT = 10.0


class FakeNode:
    """What the Receiver needs of a Node: its name and the registry (no master)."""

    caller_id = "/web_test"

    def __init__(self) -> None:
        self.subscriptions: dict = {}
        #: the protocols it speaks: TCPROS (the fake publishers speak nothing else)
        self.protocols = [TCPROSHandler(lambda: ("127.0.0.1", 1))]

    def resolve_topic_name(self, name: str) -> str:
        return name

    def add_subscription(self, sub, announce: bool = True) -> None:
        self.subscriptions[sub.resolved_name] = sub

    def remove_subscription(self, sub) -> None:
        self.subscriptions.pop(sub.resolved_name, None)


class Publisher:
    """A publisher's two servers for any topic: requestTopic (XML-RPC) and TCPROS. It answers
    each subscriber with ``reply`` (header fields) and keeps the sockets for the test."""

    def __init__(self, refuse: str = "", md5sum: str = String._md5sum) -> None:
        self.refuse = refuse
        self.md5sum = md5sum
        self.requests = 0
        self.conns: list = []
        self.accepted: queue.Queue = queue.Queue()
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.xmlrpc = XmlRpcServer(self, "127.0.0.1", 0)
        self.xmlrpc.start()
        self.uri = f"http://127.0.0.1:{self.xmlrpc.port}/"
        threading.Thread(target=self._accept, daemon=True).start()

    def requestTopic(self, caller_id, topic, protocols):
        self.requests += 1
        if self.refuse:
            return [-1, self.refuse, []]
        return [1, "", ["TCPROS", "127.0.0.1", self.listener.getsockname()[1]]]

    def _accept(self) -> None:
        while True:
            try:
                sock, _ = self.listener.accept()
            except OSError:
                return
            sock.settimeout(TIMEOUT)
            header = sockets.read_header(sock)
            sock.sendall(tcpros.encode_header({
                "topic": header["topic"], "type": "std_msgs/String", "md5sum": self.md5sum,
                "callerid": "/fake_pub", "message_definition": String._full_text,
                "latching": "0"}))
            self.conns.append(sock)
            self.accepted.put(sock)

    def wait_connection(self) -> socket.socket:
        """The next connection the receiver made (in the order they were accepted)."""
        try:
            return self.accepted.get(timeout=TIMEOUT)
        except queue.Empty:
            raise AssertionError("the receiver did not connect") from None

    def close(self) -> None:
        self.listener.close()
        self.xmlrpc.shutdown()
        for sock in self.conns:
            sockets.close(sock)


def frame(text: str) -> bytes:
    data = text.encode()
    body = struct.pack("<I", len(data)) + data
    return struct.pack("<I", len(body)) + body


class Inbox:
    def __init__(self) -> None:
        self.items: list = []
        self.cond = threading.Condition()

    def __call__(self, data, header) -> None:
        with self.cond:
            self.items.append((bytes(data), header))
            self.cond.notify_all()

    def wait(self, n: int) -> list:
        with self.cond:
            assert self.cond.wait_for(lambda: len(self.items) >= n, TIMEOUT), self.items
            return list(self.items)


@pytest.fixture
def receiver():
    r = Receiver(FakeNode(), workers=2)
    yield r
    r.close()


@pytest.mark.slow  # over half a CPU-second of its own
def test_many_subscriptions_share_one_receive_thread(receiver):
    pub = Publisher()
    before = threading.active_count()
    inboxes = []
    try:
        for i in range(300):
            inbox = Inbox()
            inboxes.append(inbox)
            sub = receiver.subscribe(f"/t{i}", RawString, inbox)
            sub.publisher_update([pub.uri])
        conns = [pub.wait_connection() for _ in range(300)]
        for n, sock in enumerate(conns):
            sock.sendall(frame(f"m{n}"))
        for inbox in inboxes:
            (data, header), = inbox.wait(1)
            assert header["callerid"] == "/fake_pub"
        got = sorted(struct.unpack_from("<I", i.items[0][0])[0] for i in inboxes)
        assert got == [len(f"m{n}") for n in sorted(range(300), key=lambda n: len(f"m{n}"))]
        # the receiver's own threads: its connect workers and its one loop, none per
        # subscription (counted by name: other tests' threads may come and go meanwhile)
        mine = [t.name for t in threading.enumerate() if t.name.startswith("minros-web-")]
        assert len(mine) <= 3, mine
        assert threading.active_count() - before < 300
        sub = receiver.node.subscriptions["/t3"]
        stats = sub.get_stats()
        assert stats[0] == "/t3" and stats[1][0][2] == 1 and stats[1][0][4] is True
        assert sub.get_stats_info()[0][1] == pub.uri
    finally:
        pub.close()


def test_a_dropped_connection_is_made_again_while_the_publisher_is_listed(receiver):
    pub = Publisher()
    inbox = Inbox()
    try:
        sub = receiver.subscribe("/again", RawString, inbox)
        sub.publisher_update([pub.uri])
        first = pub.wait_connection()
        first.sendall(frame("one") + frame("tw"))  # two frames in one segment
        inbox.wait(2)
        sockets.close(first)  # the publisher drops us: retried after 0.5 s
        second = pub.wait_connection()
        second.sendall(frame("three"))
        assert [d[4:] for d, _ in inbox.wait(3)] == [b"one", b"tw", b"three"]
        sub.publisher_update([])  # the publisher is gone from the master
        sockets.close(second)
        time.sleep(1.5)
        assert pub.requests == 2 and sub.by_uri == {}
    finally:
        pub.close()


def test_a_broken_stream_is_closed_and_tried_again(receiver):
    pub = Publisher()
    inbox = Inbox()
    try:
        sub = receiver.subscribe("/broken", RawString, inbox)
        sub.publisher_update([pub.uri])
        first = pub.wait_connection()
        first.sendall(frame("ok") + struct.pack("<I", 2_000_000_000))  # over the frame limit
        pub.wait_connection().sendall(frame("fine"))
        assert [d[4:] for d, _ in inbox.wait(2)] == [b"ok", b"fine"]
    finally:
        pub.close()


@pytest.mark.parametrize("kind", ["refused", "wrong md5", "gone"])
def test_a_publisher_that_will_not_serve_the_topic_is_given_up(receiver, kind):
    pub = Publisher(refuse="no such topic" if kind == "refused" else "",
                    md5sum="0" * 32 if kind == "wrong md5" else String._md5sum)
    uri = pub.uri
    if kind == "gone":
        pub.close()
    try:
        sub = receiver.subscribe(f"/{kind.replace(' ', '_')}", RawString, Inbox())
        sub.publisher_update([uri])
        deadline = time.monotonic() + TIMEOUT
        while sub.by_uri and time.monotonic() < deadline:
            time.sleep(0.05)
        assert sub.by_uri == {}  # forgotten: no retry
        requests = pub.requests
        time.sleep(1.2)
        assert pub.requests == requests
    finally:
        pub.close()


def test_a_topic_the_node_subscribes_to_itself_is_refused(receiver):
    receiver.node.subscriptions["/clock"] = object()
    with pytest.raises(ValueError, match="already subscribes to /clock"):
        receiver.subscribe("/clock", RawString, Inbox())


def test_unsubscribe_closes_the_connections(receiver):
    pub = Publisher()
    try:
        sub = receiver.subscribe("/bye", RawString, Inbox())
        sub.publisher_update([pub.uri])
        sock = pub.wait_connection()
        receiver.unsubscribe(sub)
        assert "/bye" not in receiver.node.subscriptions
        sock.settimeout(TIMEOUT)
        assert sock.recv(10) == b""  # the receiver closed its end
    finally:
        pub.close()
