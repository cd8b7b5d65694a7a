"""TCPROS topic connections (transport/tcpros_pubsub.py) over an in-memory stream: both ends,
the header exchange, the publisher's queue under backpressure, half-sent frames, a subscriber
that stops reading or leaves, a publication's latched message. No sockets, no sleeps: every
wait is on an event of the stream or the connection."""

from __future__ import annotations

import threading
from typing import Any, List

import pytest

from memstream import MemoryStream
from minros.client.msg import AnyMsg, serialize_frame
from minros.client.publication import Publication
from minros.transport.tcpros_pubsub import TCPROSHandler, TCPROSReceiver, TCPROSSender
from minros.wire import tcpros
from minros.wire.handshake import Handshake, Rejected, Role

TIMEOUT = 5.0


class FakeNode:
    caller_id = "/talker"

    @staticmethod
    def is_shutdown() -> bool:
        return False


class Ended:
    """An on_close callback to wait for."""

    def __init__(self) -> None:
        self.event = threading.Event()
        self.transports: List[Any] = []

    def __call__(self, transport: Any) -> None:
        self.transports.append(transport)
        self.event.set()


def frames_of(payloads):
    return [serialize_frame(AnyMsg(p)) for p in payloads]


def wire_bytes(payloads) -> bytes:
    """The frames as one byte string (a big frame is a tuple of buffers)."""
    return b"".join(b"".join(f) if isinstance(f, tuple) else f for f in frames_of(payloads))


def read_frames(stream: MemoryStream, count: int, last: bytes | None = None) -> List[bytes]:
    """What a subscriber reads: ``count`` frames (or up to the frame ``last``), parsed as
    they come."""
    reader = tcpros.FrameReader()
    out: List[bytes] = []
    while len(out) < count if last is None else not out or out[-1] != last:
        chunk = stream.recv(1000)
        if not chunk:
            break
        out.extend(bytes(f) for f in reader.feed(chunk))
    return out


def sender_pair(queue_size, capacity=1 << 20):
    pub_end, sub_end = MemoryStream.pair(capacity)
    ended = Ended()
    sender = TCPROSSender(pub_end, "/t", queue_size, ended)
    handshake = Handshake(Role.PUBLISHER, {"topic": "/t", "type": "std_msgs/String",
                                           "md5sum": "*", "callerid": "/talker"})
    sender.negotiate(handshake, {"topic": "/t", "md5sum": "*", "callerid": "/listener"})
    header, used = tcpros.read_header_block(sub_end.recv(4096))
    assert header["callerid"] == "/talker"
    return sender, sub_end, ended


@pytest.mark.parametrize("queue_size", [None, 0])
def test_the_stream_is_byte_exact_under_backpressure(queue_size):
    """Frames of all sizes through a 4 KiB buffer: partial sends resume in order (synchronous
    and queued; queue_size=0 is unbounded, so nothing may be dropped)."""
    sender, sub_end, _ = sender_pair(queue_size, capacity=4096)
    payloads = [bytes([i % 256]) * size for i, size in enumerate([10, 70_000, 5, 200_000, 3000, 1])]
    received: List[bytes] = []
    reading = threading.Thread(target=lambda: received.extend(read_frames(sub_end, len(payloads))))
    reading.start()
    for frame in frames_of(payloads):
        sender.send(frame)
    reading.join(TIMEOUT)
    sender.close()
    assert received == payloads


def test_a_full_queue_drops_the_oldest_but_never_the_half_sent_frame():
    sender, sub_end, _ = sender_pair(queue_size=2, capacity=4096)
    first = serialize_frame(AnyMsg(b"A" * 10_000))  # the kernel (here: 4 KiB) takes part of it
    sender.send(first)
    assert sub_end.wait_pending(lambda n: n == 4096)
    later = frames_of([bytes([i]) * 100 for i in range(1, 8)])
    for frame in later:
        sender.send(frame)  # never blocks: the subscriber reads nothing meanwhile
    got = read_frames(sub_end, 0, last=bytes([7]) * 100)  # the newest is kept
    assert got[0] == b"A" * 10_000  # the half-sent frame was finished, not dropped
    # at most two queued, and one the writer may have taken with the half-sent frame; in order
    kept = [g[0] for g in got[1:]]
    assert 1 <= len(kept) <= 3 and kept == sorted(kept) and all(g == bytes([g[0]]) * 100 for g in got[1:])
    sender.close()


def test_a_full_queue_of_big_frames_waits_for_room_then_drops_the_oldest(monkeypatch):
    """A publisher a whole queue ahead waits (a frame's send time, at most BACKOFF_MAX) for
    the writer to take a frame instead of dropping at once; a subscriber that reads nothing
    costs it that wait and no more, and the queue keeps the newest frame."""
    from minros.transport import tcpros_pubsub

    sender, sub_end, _ = sender_pair(queue_size=1, capacity=4096)
    waits: List[float] = []
    wait = sender.space.wait
    monkeypatch.setattr(sender.space, "wait", lambda t: waits.append(t) or wait(t))
    big = [bytes([i]) * 300_000 for i in range(1, 6)]  # 0.3 ms each at BACKOFF_RATE
    sending = threading.Thread(target=lambda: [sender.send(f) for f in frames_of(big)])
    sending.start()
    sending.join(TIMEOUT)
    assert not sending.is_alive()  # the stalled subscriber did not hold the publisher
    assert waits and all(w == pytest.approx(300_004 / tcpros_pubsub.BACKOFF_RATE) for w in waits)
    got = read_frames(sub_end, 0, last=big[-1])
    assert got[0] == big[0] and got[-1] == big[-1]  # the half-sent first, the newest last
    sender.close()


def test_close_interrupts_a_synchronous_send_to_a_stalled_subscriber():
    """queue_size=None sends all before returning; a subscriber that stopped reading must not
    keep unregister or shutdown waiting."""
    sender, sub_end, _ = sender_pair(queue_size=None, capacity=4096)
    sending = threading.Thread(target=sender.send, args=(bytes(8 << 20),), daemon=True)
    sending.start()
    assert sub_end.wait_pending(lambda n: n == 4096)  # the send is under way, and stuck
    assert sending.is_alive()
    closing = threading.Thread(target=sender.close, daemon=True)
    closing.start()
    closing.join(TIMEOUT)
    sending.join(TIMEOUT)
    assert not closing.is_alive() and not sending.is_alive() and sender.done


def test_a_subscriber_that_leaves_is_noticed_without_a_publish():
    sender, sub_end, ended = sender_pair(queue_size=10)
    sub_end.close()
    assert ended.event.wait(TIMEOUT)
    assert ended.transports == [sender] and sender.done
    sender.send(b"\x01\x00\x00\x00x")  # a publish after that is a no-op, not an error


def test_the_subscribers_end_cuts_frames_across_receives_and_ends_cleanly():
    pub_end, sub_end = MemoryStream.pair()
    receiver = TCPROSReceiver(sub_end, "/t", buff_size=4096, reuse_big=False)
    data = wire_bytes([b"one", b"x" * 100_000, b"three"])
    pub_end.sendall(data[:5])
    assert receiver.receive() == []  # a length prefix and one byte: no frame yet
    pub_end.sendall(data[5:])
    got: List[bytes] = []
    while len(got) < 3:
        got.extend(bytes(f) for f in receiver.receive())
    assert got == [b"one", b"x" * 100_000, b"three"]
    assert receiver.stat_bytes == len(data)
    pub_end.shutdown(2)
    assert receiver.receive() is None


def test_a_publisher_gone_mid_frame_is_an_error():
    pub_end, sub_end = MemoryStream.pair()
    receiver = TCPROSReceiver(sub_end, "/t", buff_size=4096, reuse_big=False)
    pub_end.sendall(frames_of([b"whole"])[0] + b"\x10\x00\x00\x00half")
    assert [bytes(f) for f in receiver.receive()] == [b"whole"]
    pub_end.close()
    with pytest.raises(tcpros.FrameError, match="middle of a frame"):
        receiver.receive()


def publication(latch=None) -> Publication:
    from std_msgs.msg import String

    pub = Publication(FakeNode(), "/chatter", "/chatter", String)
    pub.queue_size = 10
    if latch is not None:
        pub.is_latch = True
        pub.latch = String(latch)
    return pub


def subscriber_handshake(md5: str = "992ce8a1687cec8c8bd883ec73ca41d1") -> Handshake:
    return Handshake(Role.SUBSCRIBER, {"topic": "/chatter", "md5sum": md5, "type": "std_msgs/String",
                                       "callerid": "/listener", "tcp_nodelay": "0"})


def accept_in_thread(pub_end, pub) -> threading.Thread:
    """The node's TCPROS server: read the opening header, hand the stream to the handler."""
    from minros.wire import sockets

    def serve():
        try:
            TCPROSHandler(lambda: ("h", 1)).accept(pub_end, sockets.read_header(pub_end), pub)
        except Rejected:
            pass

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    return thread


def test_a_subscriber_connects_to_a_publication_and_gets_the_latched_message_first():
    pub = publication(latch="latched")
    pub_end, sub_end = MemoryStream.pair()
    serving = accept_in_thread(pub_end, pub)
    receiver = TCPROSReceiver(sub_end, "/chatter", buff_size=4096, reuse_big=True)
    receiver.negotiate(subscriber_handshake())
    serving.join(TIMEOUT)
    assert receiver.header["latching"] == "1" and receiver.header["callerid"] == "/talker"
    assert pub.get_num_connections() == 1 and pub.connections[0].header["callerid"] == "/listener"
    from std_msgs.msg import String

    pub.publish(String("live"))
    got: List[bytes] = []
    while len(got) < 2:
        got.extend(bytes(f) for f in receiver.receive())
    assert [String().deserialize(f).data for f in got] == ["latched", "live"]
    assert pub.get_stats()[2][0][2] == 2  # messages sent on the connection
    pub.close()
    assert receiver.receive() is None


def test_a_refused_subscriber_reads_the_publishers_reason():
    pub = publication()
    pub_end, sub_end = MemoryStream.pair()
    serving = accept_in_thread(pub_end, pub)
    receiver = TCPROSReceiver(sub_end, "/chatter", buff_size=4096, reuse_big=True)
    with pytest.raises(Rejected, match=r"remote error reported: Client \[/listener\] wants topic"):
        receiver.negotiate(subscriber_handshake(md5="0" * 32))
    serving.join(TIMEOUT)
    assert pub.get_num_connections() == 0
    pub.closed = True
    pub_end, sub_end = MemoryStream.pair()
    serving = accept_in_thread(pub_end, pub)
    receiver = TCPROSReceiver(sub_end, "/chatter", buff_size=4096, reuse_big=True)
    with pytest.raises(Rejected, match=r"Internal error processing topic \[/chatter\]"):
        receiver.negotiate(subscriber_handshake())
    serving.join(TIMEOUT)


def test_the_handler_refuses_answers_it_cannot_use():
    handler = TCPROSHandler(lambda: ("h", 1))
    assert handler.offer() == ["TCPROS"] and handler.answer("/t", ["TCPROS"]) == ["TCPROS", "h", 1]
    for answer in (["TCPROS", "h"], ["TCPROS", "h", "80"], ["TCPROS", 5, 80], ["TCPROS", "h", True]):
        with pytest.raises(ValueError, match="invalid protocol choice"):
            handler.connect(answer, "/t", 4096, reuse_big=False, tcp_nodelay=False)
    assert handler.claims({"topic": "/t"}, "TCPROS") and not handler.claims({"service": "/s"}, "TCPROS")
    assert not handler.claims({"topic": "/t"}, "MINROSSHM")  # the Unix socket's is shared memory's
