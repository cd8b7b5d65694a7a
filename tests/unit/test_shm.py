"""MINROSSHM, the shared-memory transport: its pure parts (negotiation, the records, the
publisher's slot queue) without sockets, then both ends over a real Unix socketpair (file
descriptors pass only over one): messages in place, slots given back, the queue under a slow
subscriber, and every failure falling back (FallBack) instead of crashing or hanging."""

from __future__ import annotations

import errno
import os
import select
import socket
import struct
import threading
from typing import Any, List

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from memstream import MemoryStream
from minros.client.msg import AnyMsg, frame_len, serialize_frame
from minros.msgs import get_message_class, reader_for
from minros.transport import shm as shm_transport
from minros.transport.base import FallBack
from minros.transport.shm import ShmReceiver, ShmSender, own
from minros.transport.shm import segment as shm_segment
from minros.wire import shm, sockets
from minros.wire.handshake import Handshake, Role

pytestmark = pytest.mark.skipif(not shm_transport.supported(), reason="no memfd on this system")

TIMEOUT = 5.0
BOOT = "de672902-e6ff-41ba-bfe0-bc31c6830c4c"


# --------------------------------------------------------------------------- negotiation


def test_offer_and_answer_on_one_host():
    offer = shm.offer(BOOT)
    assert offer == ["MINROSSHM", 1, BOOT]
    assert shm.check_offer(offer, BOOT) is None
    assert shm.parse_answer(shm.answer("minros-shm.1.ab", BOOT), BOOT) == "minros-shm.1.ab"


@pytest.mark.parametrize("offer, why", [
    (["MINROSSHM", 1, "another-boot-id"], "another host"),
    (["MINROSSHM", 2, BOOT], "version 2"),
    (["MINROSSHM", True, BOOT], "version True"),
    (["MINROSSHM", 1], "not a MINROSSHM offer"),
    (["MINROSSHM", 1, 7], "another host"),
    (["MINROSSHM", 1, ""], "another host"),
])
def test_a_publisher_declines_other_hosts_and_versions(offer, why):
    assert why in shm.check_offer(offer, BOOT)


def test_an_unknown_kernel_takes_no_offer():
    """A publisher that cannot read its boot id cannot tell the host: it declines."""
    assert shm.check_offer(shm.offer(""), "") is not None


@pytest.mark.parametrize("answer", [
    ["MINROSSHM", "", BOOT], ["MINROSSHM", 7, BOOT], ["MINROSSHM", "a\0b", BOOT],
    ["MINROSSHM", "x" * 200, BOOT], ["MINROSSHM", "name"], ["TCPROS", "h", 1],
])
def test_a_subscriber_rejects_answers_it_cannot_use(answer):
    with pytest.raises(ValueError):
        shm.parse_answer(answer, BOOT)


def test_an_answer_from_another_kernel_is_refused():
    with pytest.raises(ValueError, match="another host"):
        shm.parse_answer(shm.answer("n", "other"), BOOT)


def test_slot_counts_and_sizes():
    assert shm.SLOTS == shm.WINDOW + 1 == 3  # whatever the queue_size: the window and one ahead
    assert shm.grown_slot_size(6220854) == 6221824  # the first message, rounded to pages
    assert shm.grown_slot_size(6220855, 6221824) == shm.page_round(6221824 * 3 // 2)
    assert shm.grown_slot_size(20 << 20, 6221824) == 20 << 20


# --------------------------------------------------------------------------- records


def records() -> bytes:
    frame = serialize_frame(AnyMsg(b"hello"))
    return b"".join([
        shm.segment(1, 3, 8192),
        shm.slot(1, 2, 0, 100, 7),
        shm.INLINE + frame,
        shm.fallback("no memory"),
    ])


def parse(data: bytes, chunk: int) -> List[Any]:
    reader = shm.NoticeReader()
    out: List[Any] = []
    for i in range(0, len(data), chunk):
        part = data[i:i + chunk]
        space = reader.space()
        space[:len(part)] = part
        out.extend(reader.received(len(part)))
    assert reader.pending == 0
    return out


@pytest.mark.parametrize("chunk", [1, 3, 7, 28, 1000])
def test_records_survive_any_split(chunk):
    out = parse(records(), chunk)
    assert out == [(1, 3, 8192, 4096 + 3 * 8192), (1, 2, 0, 100, 7), b"hello", "no memory"]
    assert [type(r) for r in out] == [shm.Segment, shm.Slot, bytes, shm.Fallback]
    assert out[1].slot == 2 and out[1].seq == 7 and out[0].slot_size == 8192


def test_a_largest_inline_message_fits_after_a_partial_one():
    body = b"x" * (shm.INLINE_LIMIT - 5)
    one = shm.INLINE + struct.pack("<I", len(body)) + body
    assert [len(m) for m in parse(one * 3, 50_000)] == [len(body)] * 3


@pytest.mark.parametrize("garbage, error", [
    (b"JUNK" + bytes(30), "unknown record b'JUNK'"),
    (shm.INLINE + struct.pack("<I", 1 << 30), "inline message of 1073741824 bytes"),
    (struct.pack("<4sIIIQ", b"SEGM", 1, 0, 8192, 4096), "0 slots"),
    (struct.pack("<4sIIIQ", b"SEGM", 1, 1000, 8192, 4096 + 1000 * 8192), "1000 slots"),
    (struct.pack("<4sIIIQ", b"SEGM", 1, 2, 5000, 4096 + 10000), "slots of 5000 bytes"),
    (struct.pack("<4sIIIQ", b"SEGM", 1, 2, 8192, 1 << 40), "1099511627776 bytes"),
    (b"FALL" + struct.pack("<I", 1 << 20), "reason of 1048576 bytes"),
])
def test_garbage_records_are_errors_not_allocations(garbage, error):
    with pytest.raises(shm.ShmError, match=error):
        parse(garbage, 1000)


def test_done_records_and_garbage_from_a_subscriber():
    reader = shm.DoneReader()
    data = shm.done(1, 2) + shm.done(3, 4)
    reader.space()[:len(data)] = data
    assert reader.received(len(data)) == [(1, 2), (3, 4)]
    reader.space()[:12] = b"NOPE" + bytes(8)
    with pytest.raises(shm.ShmError, match="unknown record b'NOPE'"):
        reader.received(12)


@given(st.binary(max_size=400), st.integers(1, 64))
@settings(max_examples=300, deadline=None)
def test_fuzz_the_notice_reader_raises_only_shm_errors(data, chunk):
    reader = shm.NoticeReader()
    try:
        for i in range(0, len(data), chunk):
            part = data[i:i + chunk]
            reader.space()[:len(part)] = part
            reader.received(len(part))
    except shm.ShmError:
        pass


def test_the_segment_header_must_match_its_announcement():
    seg = shm.Segment((2, 3, 8192, 4096 + 3 * 8192))
    shm.check_segment_header(shm.segment_header(2, 3, 8192), seg)
    with pytest.raises(shm.ShmError, match="contradicts"):
        shm.check_segment_header(shm.segment_header(2, 4, 8192), seg)
    with pytest.raises(shm.ShmError, match="not a MINROSSHM segment"):
        shm.check_segment_header(bytes(64), seg)
    with pytest.raises(shm.ShmError, match="too small"):
        shm.check_segment_header(b"MINROSHM", seg)


# --------------------------------------------------------------------------- the slot table


def write(table: shm.SlotTable, length: int = 100) -> int:
    index = table.acquire()
    assert index is not None
    table.queued(index)
    return index


def test_the_window_holds_two_slots_and_done_frees_them():
    table = shm.SlotTable()
    a = write(table)
    assert table.room()
    assert table.announce(a, 0, 100)[:4] == b"SLOT"
    b = write(table)
    table.announce(b, 0, 100)
    c = write(table)
    assert not table.room()  # two in the subscriber's hands: the third waits
    assert table.acquire() is None  # and nothing is free to write
    assert table.counts() == {"free": 0, "writing": 0, "queued": 1, "notified": 2}
    table.done(1, a)
    assert table.room()
    table.announce(c, 0, 100)
    table.done(1, b)
    table.done(1, c)
    assert table.counts()["free"] == 3


def test_a_dropped_frame_frees_its_slot():
    table = shm.SlotTable()
    index = write(table)
    table.abandon(index)  # a queued frame the queue dropped, or a loan given back
    assert table.counts()["free"] == 3


def test_done_for_a_slot_not_held_is_a_protocol_error():
    table = shm.SlotTable()
    with pytest.raises(shm.ShmError, match="does not hold"):
        table.done(1, 0)
    table.announce(write(table), 0, 100)
    table.done(1, 0)
    with pytest.raises(shm.ShmError):
        table.done(1, 0)  # twice


def test_a_new_segment_keeps_the_held_slots_of_the_old_one_in_the_window():
    table = shm.SlotTable()
    table.announce(write(table), 0, 100)
    table.announce(write(table), 0, 100)
    table.resize(3, 2)
    index = write(table)
    assert not table.room()  # generation 1's two slots are still the subscriber's
    table.done(1, 0)
    assert table.announce(index, 0, 100)[:8] == shm.slot(2, 0, 0, 100, 3)[:8]


# --------------------------------------------------------------------------- both ends


class Closed:
    def __init__(self) -> None:
        self.event = threading.Event()

    def __call__(self, transport: Any) -> None:
        self.event.set()


#: both ends run over a Unix socketpair (descriptors pass as in a real connection) and over
#: tests/memstream.py's in-memory stream (as TCPROS's ends are tested)
STREAMS = ["unix", "memory"]


def stream_pair(kind: str, capacity: int = 1 << 20):
    if kind == "memory":
        return MemoryStream.pair(capacity)
    return socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)


def connect(queue_size=10, topic="/t", stream="unix"):
    """A publisher's and a subscriber's end over a stream pair, negotiated."""
    pub_sock, sub_sock = stream_pair(stream)
    closed = Closed()
    sender = ShmSender(pub_sock, topic, queue_size, closed)
    receiver = ShmReceiver(sub_sock, topic)
    fields = {"topic": topic, "md5sum": "*", "callerid": "/listener", "type": "*"}
    thread = threading.Thread(target=receiver.negotiate,
                              args=(Handshake(Role.SUBSCRIBER, fields),), daemon=True)
    thread.start()
    header = sockets.read_header(pub_sock)
    sender.negotiate(Handshake(Role.PUBLISHER, {"topic": topic, "type": "*", "md5sum": "*",
                                                "callerid": "/talker"}), header)
    thread.join(TIMEOUT)
    assert receiver.header["callerid"] == "/talker"
    return sender, receiver, closed


def settled(sender: ShmSender, predicate) -> bool:
    """Wait until ``predicate()`` holds for the sender's state (its threads notify its
    condition on every change); False after TIMEOUT."""
    with sender.cond:
        return sender.cond.wait_for(predicate, TIMEOUT)


def payload(n: int, size: int) -> bytes:
    return bytes([n % 251]) * size


def receive(receiver: ShmReceiver, count: int, views: bool = False) -> List[Any]:
    """The next ``count`` frames (as bytes, or as they come: views of slots)."""
    out: List[Any] = []
    while len(out) < count:
        frames = receiver.receive()
        assert frames is not None
        out.extend(frames if views else (bytes(f) for f in frames))
    return out


@pytest.fixture(params=STREAMS)
def pair(request):
    sender, receiver, closed = connect(stream=request.param)
    yield sender, receiver, closed
    sender.close()
    receiver.close()


def test_large_messages_come_from_the_slot_small_ones_inline(pair):
    sender, receiver, _ = pair
    big = [payload(n, 300_000) for n in range(3)]
    for data in big:
        sender.send(serialize_frame(AnyMsg(data)))
    sender.send(serialize_frame(AnyMsg(b"small")))
    frames = receiver.receive()
    while len(frames) < 4:
        frames += receiver.receive()
    assert [f.__class__ for f in frames] == [memoryview, memoryview, memoryview, bytes]
    assert [bytes(f) for f in frames] == big + [b"small"]
    assert frames[0].readonly
    seg = sender.memory.segment
    assert seg is not None and seg.slots == shm.SLOTS and seg.slot_size == shm.page_round(300_004)
    assert settled(sender, lambda: sender.stat_msgs == 4)  # counted once wholly sent
    assert receiver.info().startswith("MINROSSHM connection")


def test_a_slot_goes_back_when_the_subscriber_asks_again(pair):
    sender, receiver, _ = pair
    for n in range(2):
        sender.send(serialize_frame(AnyMsg(payload(n, 100_000))))
    got = receive(receiver, 2)
    assert sender.slots.in_flight == 2  # held while the callbacks run
    sender.send(serialize_frame(AnyMsg(payload(2, 100_000))))
    got += receive(receiver, 1)  # asking again gave the first two back
    assert got == [payload(n, 100_000) for n in range(3)]
    assert settled(sender, lambda: sender.slots.in_flight == 1)


def test_the_publishing_thread_takes_slots_back_itself(monkeypatch):
    """A publisher copying frames back to back holds the GIL: when the window is full it reads
    the subscriber's DONE records itself, not waiting for its watcher thread to get the GIL
    (which took up to the 5 ms switch interval per slot: most frames were dropped)."""
    idle = threading.Event()
    monkeypatch.setattr(ShmSender, "_watch", lambda self: idle.wait(TIMEOUT))  # a deaf watcher
    sender, receiver, _ = connect()
    try:
        for n in range(2):
            sender.send(serialize_frame(AnyMsg(payload(n, 100_000))))
        got = receive(receiver, 2)
        assert sender.slots.in_flight == 2
        third: List[Any] = []
        asking = threading.Thread(target=lambda: third.extend(receive(receiver, 1)), daemon=True)
        asking.start()  # gives the two slots back, then waits for the next frame
        readable, _, _ = select.select([sender.stream], [], [], TIMEOUT)
        assert readable, "the subscriber's DONE records never came"
        sender.send(serialize_frame(AnyMsg(payload(2, 100_000))))
        asking.join(TIMEOUT)
        assert got + third == [payload(n, 100_000) for n in range(3)]
        assert sender.slots.in_flight == 1
    finally:
        idle.set()
        sender.close()
        receiver.close()


@pytest.mark.parametrize("stream", STREAMS)
def test_a_slow_subscriber_never_blocks_the_publisher_and_sees_the_latest(stream):
    sender, receiver, _ = connect(queue_size=2, stream=stream)
    try:
        for n in range(50):  # the subscriber reads nothing meanwhile
            sender.send(serialize_frame(AnyMsg(payload(n, 200_000))))
        got = receive(receiver, 2)  # the window: the first two
        got += receive(receiver, 2)  # then what the queue kept: the last two
        assert got == [payload(n, 200_000) for n in (0, 1, 48, 49)]
        assert sender.queue.dropped == 46
    finally:
        sender.close()
        receiver.close()


def test_a_growing_message_gets_a_new_segment(pair):
    sender, receiver, _ = pair
    sender.send(serialize_frame(AnyMsg(payload(1, 100_000))))
    first = receive(receiver, 1, views=True)
    sender.send(serialize_frame(AnyMsg(payload(2, 500_000))))
    second = receive(receiver, 1)
    assert bytes(first[0]) == payload(1, 100_000) and second == [payload(2, 500_000)]
    assert sender.memory.segment.generation == 2
    sender.send(serialize_frame(AnyMsg(b"x")))
    receive(receiver, 1)
    assert list(receiver.maps) == [2]  # the old mapping went once its frames were done
    assert bytes(first[0]) == payload(1, 100_000)  # and a view kept keeps its memory


def test_the_message_is_read_in_place_and_a_kept_one_is_made_its_own(pair):
    sender, receiver, _ = pair
    Image = get_message_class("sensor_msgs/Image")
    img = Image(height=100, width=1000, encoding="mono8", step=1000, data=payload(7, 100_000))
    sender.send(serialize_frame(img))
    frame = receive(receiver, 1, views=True)[0]
    msg = receiver.message_reader(Image)(frame)
    assert msg.data.__class__ is memoryview and msg.data.obj is not None
    assert bytes(msg.data) == img.data and msg.header.seq == img.header.seq
    kept = [msg]
    receiver.settle(msg)  # referenced from the list: its data is copied out
    assert kept[0].data.__class__ is bytes and kept[0].data == img.data
    other = receiver.message_reader(Image)(frame)
    receiver.settle(other)  # nobody keeps it: left as it is
    assert other.data.__class__ is memoryview


def test_own_copies_views_everywhere_in_a_message():
    np = pytest.importorskip("numpy")
    buf = bytearray(b"abcdefgh")
    Image = get_message_class("sensor_msgs/Image")
    img = Image(data=memoryview(buf)[2:6])
    own(img)
    assert img.data == b"cdef" and img.data.__class__ is bytes
    any_msg = AnyMsg(memoryview(buf))
    own(any_msg)
    assert any_msg._buff == bytes(buf)
    Cloud = get_message_class("sensor_msgs/PointCloud2")
    numpy_cloud_cls = Cloud._context.get_numpy_class(Cloud)
    cloud = numpy_cloud_cls()
    cloud.__class__.__init__(cloud)
    cloud.data = np.frombuffer(buf, dtype=np.uint8)
    own(cloud)
    buf[0:1] = b"z"
    assert bytes(cloud.data) == b"abcdefgh"


def test_reader_in_place_gives_views_only_of_byte_arrays():
    Image = get_message_class("sensor_msgs/Image")
    img = Image(height=1, width=3, encoding="rgb8", step=9, data=bytes(range(9)))
    img.header.frame_id = "cam"
    body = memoryview(bytes(serialize_frame(img)))[4:]
    msg = reader_for(Image, in_place=True)(body)
    assert msg.__class__ is Image and msg.data.__class__ is memoryview
    assert msg == img and msg.header.frame_id == "cam"
    assert reader_for(Image)(body).data.__class__ is bytes


# --------------------------------------------------------------------------- failures


def raw_pair():
    """A subscriber's end and the raw socket a misbehaving publisher writes to."""
    pub_sock, sub_sock = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    receiver = ShmReceiver(sub_sock, "/t")
    receiver.latching = False
    return pub_sock, receiver


def send_fd(sock: socket.socket, data: bytes, fd: int) -> None:
    sock.sendmsg([data], [(socket.SOL_SOCKET, socket.SCM_RIGHTS, struct.pack("i", fd))])


def sealed_memfd(size: int, seal: bool = True) -> int:
    import fcntl

    fd = os.memfd_create("test", os.MFD_CLOEXEC | os.MFD_ALLOW_SEALING)
    os.ftruncate(fd, size)
    if seal:
        fcntl.fcntl(fd, fcntl.F_ADD_SEALS, fcntl.F_SEAL_SHRINK | fcntl.F_SEAL_GROW)
    return fd


def fds_open() -> int:
    return len(os.listdir("/proc/self/fd"))


@pytest.mark.parametrize("case", ["garbage", "vanished slot", "slot outside", "wrong frame",
                                  "fd without segment", "segment without fd", "unsealed",
                                  "short segment", "not a segment"])
def test_a_publisher_breaking_the_protocol_means_fallback(case):
    pub_sock, receiver = raw_pair()
    before = fds_open()
    size = shm.HEADER_SIZE + 3 * 8192
    good_header = shm.segment_header(1, 3, 8192)
    try:
        if case == "garbage":
            pub_sock.sendall(b"\x00\x01garbage notification" * 4)
        elif case == "vanished slot":
            pub_sock.sendall(shm.slot(5, 0, 0, 100, 1))
        elif case in ("slot outside", "wrong frame"):
            fd = sealed_memfd(size)
            os.pwrite(fd, good_header, 0)
            send_fd(pub_sock, shm.segment(1, 3, 8192), fd)
            os.close(fd)
            pub_sock.sendall(shm.slot(1, 7, 0, 100, 1) if case == "slot outside"
                             else shm.slot(1, 0, 0, 100, 1))
        elif case == "fd without segment":
            fd = sealed_memfd(size)
            send_fd(pub_sock, shm.slot(1, 0, 0, 100, 1), fd)
            os.close(fd)
        elif case == "segment without fd":
            pub_sock.sendall(shm.segment(1, 3, 8192))
        else:
            fd = sealed_memfd(size if case != "short segment" else 8192, case != "unsealed")
            if case != "not a segment":
                os.pwrite(fd, good_header, 0)
            send_fd(pub_sock, shm.segment(1, 3, 8192), fd)
            os.close(fd)
        with pytest.raises(FallBack) as raised:
            for _ in range(3):
                receiver.receive()
        assert "broke the shared-memory protocol" in str(raised.value)
    finally:
        receiver.close()
        pub_sock.close()
    assert fds_open() <= before  # every descriptor it was sent is closed


def test_a_fall_record_means_fallback_with_its_reason():
    pub_sock, receiver = raw_pair()
    pub_sock.sendall(shm.fallback("memfd_create: Operation not permitted"))
    with pytest.raises(FallBack, match="gave up on shared memory: memfd_create"):
        receiver.receive()
    receiver.close()
    pub_sock.close()


def test_a_publisher_gone_mid_record_is_a_frame_error_and_a_clean_end_is_none():
    from minros.wire.tcpros import FrameError

    pub_sock, receiver = raw_pair()
    pub_sock.sendall(shm.slot(1, 0, 0, 100, 1)[:10])
    pub_sock.close()
    with pytest.raises(FrameError):
        while receiver.receive() is not None:
            pass
    pub_sock, receiver = raw_pair()
    pub_sock.close()
    assert receiver.receive() is None


@pytest.mark.parametrize("failing, error", [
    ("memfd_create", OSError(errno.EPERM, "Operation not permitted")),  # seccomp, a sandbox
    ("memfd_create", OSError(errno.EMFILE, "Too many open files")),
    ("posix_fallocate", OSError(errno.ENOSPC, "No space left on device")),
    ("posix_fallocate", OSError(errno.ENOMEM, "Cannot allocate memory")),
    ("ftruncate", OSError(errno.EFBIG, "File too large")),
])
def test_the_kernel_refusing_memory_falls_back_with_one_line(monkeypatch, caplog, failing, error):
    """The publisher's memfd refused or its memory not there: the subscriber is told (FALL)
    and falls back; the publisher says it once, and declines later offers for the topic."""
    shm_segment._said.clear()

    def refuse(*args, **kwargs):
        raise error

    monkeypatch.setattr(os, failing, refuse)
    declined = {}
    sender, receiver, closed = connect(topic="/refused")
    sender.on_fallback = lambda topic, reason: declined.setdefault(topic, reason)
    try:
        with caplog.at_level("WARNING", logger="rosout"):
            for n in range(3):
                sender.send(serialize_frame(AnyMsg(payload(n, 200_000))))
            with pytest.raises(FallBack, match=error.strerror):
                receive(receiver, 1)
        lines = [r for r in caplog.records if "shared memory" in r.getMessage()]
        assert len(lines) == 1, [r.getMessage() for r in caplog.records]
        assert "/refused" in lines[0].getMessage() and "TCPROS" in lines[0].getMessage()
        assert error.strerror in declined["/refused"]
        receiver.close()
        assert closed.event.wait(TIMEOUT)  # the publisher forgets the connection
    finally:
        sender.close()
        receiver.close()


def test_a_subscriber_sending_garbage_is_disconnected(caplog):
    sender, receiver, closed = connect()
    with caplog.at_level("WARNING", logger="rosout"):
        receiver.stream.sendall(b"HELLO, THIS IS NOT A DONE RECORD")
        assert closed.event.wait(TIMEOUT)
    assert any("broke the shared-memory protocol" in r.getMessage() for r in caplog.records)
    sender.send(serialize_frame(AnyMsg(payload(1, 100_000))))  # nothing happens: it is closed
    receiver.close()


def test_the_subscriber_keeps_reading_after_the_publisher_closed(pair):
    """The memory outlives the publisher's end: a message being read stays intact."""
    sender, receiver, _ = pair
    sender.send(serialize_frame(AnyMsg(payload(3, 300_000))))
    frame = receive(receiver, 1, views=True)[0]
    sender.close()
    assert bytes(frame) == payload(3, 300_000)
    assert receiver.receive() is None


@pytest.mark.parametrize("stream", STREAMS)
def test_a_synchronous_publisher_hands_each_message_over(stream):
    sender, receiver, _ = connect(queue_size=None, stream=stream)
    got: List[bytes] = []
    thread = threading.Thread(target=lambda: got.extend(receive(receiver, 20)), daemon=True)
    thread.start()
    try:
        for n in range(20):
            sender.send(serialize_frame(AnyMsg(payload(n, 150_000 if n % 2 else 10))))
        thread.join(TIMEOUT)
        assert got == [payload(n, 150_000 if n % 2 else 10) for n in range(20)]  # none dropped
    finally:
        sender.close()
        receiver.close()


def test_cv_bridge_gives_an_image_of_a_slot_pixels_of_its_own(pair):
    """cv_bridge's passthrough image is a view of bytes data, but a copy of a slot's (it is
    usually kept beyond the callback)."""
    from minros.cv_bridge import CvBridge

    sender, receiver, _ = pair
    Image = get_message_class("sensor_msgs/Image")
    img = Image(height=100, width=1000, encoding="mono8", step=1000, data=payload(9, 100_000))
    sender.send(serialize_frame(img))
    msg = receiver.message_reader(Image)(receive(receiver, 1, views=True)[0])
    image = CvBridge().imgmsg_to_cv2(msg)
    assert image.base is None and int(image[99, 999]) == 9
    assert CvBridge().imgmsg_to_cv2(img).base is not None  # bytes: a view, as before


# --------------------------------------------------------------------------- Publisher.loan


class _Node:
    caller_id = "/talker"

    @staticmethod
    def is_shutdown() -> bool:
        return False


def publication(*conns: Any, latch: bool = False):
    from minros.client.publication import Publication

    pub = Publication(_Node(), "/t", "/t", get_message_class("sensor_msgs/Image"))
    pub.is_latch = latch
    for conn in conns:
        pub.add_connection(conn)
    return pub


def image(data: Any):
    Image = get_message_class("sensor_msgs/Image")
    return Image(height=100, width=1000, encoding="mono8", step=1000, data=data)


def test_a_loaned_array_is_published_from_its_slot_without_a_copy(pair, monkeypatch):
    sender, receiver, _ = pair
    pub = publication(sender)
    view = pub.loan(100_000)
    seg = sender.memory.segment
    assert seg is not None and not view.readonly and view.nbytes == 100_000
    assert seg.slot_size >= shm.LOAN_OFFSET + 100_000 + shm.LOAN_TAIL
    view[:] = payload(5, 100_000)  # filled in place: the slot's memory
    assert sender.slots.counts()["writing"] == 1

    def no_copy(*_args: Any) -> None:
        raise AssertionError("a loaned message was copied into a slot")

    monkeypatch.setattr(seg, "write", no_copy)
    pub.publish(image(view))
    frame = receive(receiver, 1, views=True)[0]
    msg = receiver.message_reader(image(b"").__class__)(frame)
    assert (msg.height, msg.width, msg.encoding, msg.step) == (100, 1000, "mono8", 1000)
    assert bytes(msg.data) == payload(5, 100_000) and msg.header.seq == 1
    assert pub.message_data_sent == frame_len(serialize_frame(image(payload(5, 100_000)))) - 4
    assert sender.slots.counts()["writing"] == 0 and pub._loan is None


def test_a_loan_not_published_goes_back_and_the_message_travels_as_usual(pair):
    sender, receiver, _ = pair
    pub = publication(sender)
    pub.loan(100_000)
    pub.loan(100_000)  # the first loan is cancelled
    assert sender.slots.counts()["writing"] == 1
    pub.publish(image(payload(3, 100_000)))  # a message that does not hold the loan
    assert sender.slots.counts()["writing"] == 0
    assert receive(receiver, 1)[0][-100_000:] == payload(3, 100_000)
    view = pub.loan(100_000)
    view[:] = payload(4, 100_000)
    pub.publish(image(bytes(view[:50_000]) * 2))  # a copy of part of it: no loan either
    assert sender.slots.counts()["writing"] == 0
    assert receive(receiver, 1)[0][-100_000:] == payload(4, 100_000)


def test_a_stale_loan_is_sent_as_any_message(pair):
    """A larger message made a new segment after the loan: the loan's slot is of the old
    one, so the message is copied as usual (and still correct)."""
    sender, receiver, _ = pair
    pub = publication(sender)
    view = pub.loan(100_000)
    view[:] = payload(6, 100_000)
    sender.send(serialize_frame(AnyMsg(payload(1, 900_000))))
    assert sender.memory.segment.generation == 2
    pub.publish(image(view))
    got = receive(receiver, 2)
    assert got[0] == payload(1, 900_000) and got[1][-100_000:] == payload(6, 100_000)


def test_without_a_shared_memory_subscriber_a_loan_is_plain_memory(pair):
    sender, _, _ = pair
    for pub in (publication(), publication(sender, latch=True)):
        view = pub.loan(1000)
        assert view.obj.__class__ is bytearray and view.nbytes == 1000 and not view.readonly
        assert pub._loan is None
    with pytest.raises(ValueError, match="non-negative int"):
        publication(sender).loan(-1)


def test_a_loan_of_a_publication_without_subscribers_left_goes_back(pair):
    sender, _, _ = pair
    pub = publication(sender)
    view = pub.loan(100_000)
    pub.remove_connection(sender)
    pub.publish(image(view))
    assert sender.slots.counts()["writing"] == 0 and pub._loan is None


def test_a_message_for_one_connection_leaves_the_lender_alone(pair):
    """rospy's publish(msg, connection_override): only that connection gets the message,
    even when it holds a loan of another one's slot."""
    sender, _, _ = pair

    class Other:
        takes_objects = False
        done = False

        def __init__(self) -> None:
            self.frames: List[Any] = []

        def send(self, frame: Any) -> None:
            self.frames.append(frame)

    other = Other()
    pub = publication(sender)
    view = pub.loan(100_000)
    view[:] = payload(8, 100_000)
    pub.publish(image(view), connection_override=other)
    assert len(other.frames) == 1 and frame_len(other.frames[0]) > 100_000
    assert sender.slots.counts()["writing"] == 1 and sender.stat_msgs == 0


# --------------------------------------------------------------------------- what a subscriber can do


def raw_subscriber(queue_size=10):
    """A publisher's end and the raw socket of a subscriber that reads what it likes."""
    from minros.wire import tcpros

    pub_sock, sub_sock = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    closed = Closed()
    sender = ShmSender(pub_sock, "/t", queue_size, closed)
    sub_sock.sendall(tcpros.encode_header({"topic": "/t", "md5sum": "*", "callerid": "/evil",
                                           "type": "*"}))
    sender.negotiate(Handshake(Role.PUBLISHER, {"topic": "/t", "type": "*", "md5sum": "*",
                                                "callerid": "/talker"}), sockets.read_header(pub_sock))
    sockets.read_header(sub_sock)
    return sender, sub_sock


def received_segment(sub_sock: socket.socket) -> int:
    """The descriptor that came with the SEGM record."""
    data, ancdata, _, _ = sub_sock.recvmsg(shm.INLINE_LIMIT, socket.CMSG_SPACE(16))
    assert data.startswith(shm.SEGM)
    fds = [fd for level, kind, raw in ancdata if kind == socket.SCM_RIGHTS
           for fd in struct.unpack(f"{len(raw) // 4}i", raw)]
    assert len(fds) == 1
    return fds[0]


def test_a_subscriber_cannot_write_what_every_subscriber_reads():
    """Issue 38 item 1: the memfd passed with SEGM was the publisher's own O_RDWR descriptor,
    so any same-host process that asked requestTopic could map it writable and change what
    the others receive. Now it is opened read-only and the memfd is sealed against writes
    (F_SEAL_FUTURE_WRITE): no writable mapping, no write(2), not even through a read-write
    reopening of /proc/self/fd."""
    import ctypes
    import fcntl
    import mmap

    sender, sub_sock = raw_subscriber()
    try:
        sender.send(serialize_frame(AnyMsg(payload(1, 100_000))))
        fd = received_segment(sub_sock)
        size = os.fstat(fd).st_size
        try:
            assert fcntl.fcntl(fd, fcntl.F_GETFL) & os.O_ACCMODE == os.O_RDONLY
            assert fcntl.fcntl(fd, fcntl.F_GET_SEALS) & shm_segment.F_SEAL_FUTURE_WRITE
            with pytest.raises(PermissionError):
                mmap.mmap(fd, size, flags=mmap.MAP_SHARED, prot=mmap.PROT_READ | mmap.PROT_WRITE)
            with pytest.raises(OSError):  # EBADF: not open for writing
                os.pwrite(fd, b"evil", shm.HEADER_SIZE)
            again = os.open(f"/proc/self/fd/{fd}", os.O_RDWR)  # the mode of a memfd is 0777
            try:
                with pytest.raises(PermissionError):
                    mmap.mmap(again, size, flags=mmap.MAP_SHARED,
                              prot=mmap.PROT_READ | mmap.PROT_WRITE)
                with pytest.raises(PermissionError):
                    os.pwrite(again, b"evil", shm.HEADER_SIZE)
            finally:
                os.close(again)
            # nor can a read-only mapping be made writable (mprotect)
            libc = ctypes.CDLL(None, use_errno=True)
            libc.mmap.restype = ctypes.c_void_p
            libc.mmap.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int, ctypes.c_int,
                                  ctypes.c_int, ctypes.c_long]
            libc.mprotect.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
            libc.munmap.argtypes = [ctypes.c_void_p, ctypes.c_size_t]
            address = libc.mmap(None, size, mmap.PROT_READ, mmap.MAP_SHARED, fd, 0)
            assert address not in (None, ctypes.c_void_p(-1).value)
            try:
                assert libc.mprotect(address, size, mmap.PROT_READ | mmap.PROT_WRITE) == -1
                assert ctypes.get_errno() in (errno.EACCES, errno.EPERM)
            finally:
                libc.munmap(address, size)
        finally:
            os.close(fd)
        # the publisher itself still writes (its own mapping): the next frame arrives intact
        assert sender.memory.segment is not None
        sender.memory.segment.write(0, serialize_frame(AnyMsg(payload(2, 100_000))))
    finally:
        sender.close()
        sub_sock.close()


def test_deaf_subscribers_hold_three_slots_each_not_their_queue():
    """Issue 38 item 3: subscribers that never give a slot back cost the publisher
    queue_size + 2 slots each (10 of them held 746 MB of 1080p segments). Now a segment has
    SLOTS = 3 whatever the queue_size, and the frames queued behind a deaf subscriber are the
    publication's own frames, shared by every connection as over TCPROS: the memory one
    publisher keeps for N deaf subscribers is at most 3 slots each."""
    from minros.client.publication import Publication

    deaf = [raw_subscriber(queue_size=10) for _ in range(10)]
    pub = Publication(_Node(), "/t", "/t", get_message_class("sensor_msgs/Image"))
    pub.queue_size = 10
    for sender, _ in deaf:
        pub.add_connection(sender)
    try:
        frames = 40
        for n in range(frames):  # 1 MB images, nobody reads
            pub.publish(image(payload(n, 1_000_000)))
        slot_size = deaf[0][0].memory.segment.slot_size
        for sender, _ in deaf:
            blocks = os.fstat(sender.memory.segment.fd).st_blocks * 512
            assert blocks <= shm.HEADER_SIZE + shm.SLOTS * slot_size, blocks
            assert sender.slots.in_flight == shm.WINDOW and len(sender.queue) == 10
        queued = {id(item[1]) for sender, _ in deaf for item in sender.queue.items
                  if item[0] == "frame"}
        assert len(queued) <= 10  # one frame object per message, whatever the subscribers
    finally:
        pub.close()
        for _, sub_sock in deaf:
            sub_sock.close()
