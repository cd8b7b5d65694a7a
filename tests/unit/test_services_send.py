"""The service send path without a master: serialization into parts (``client.msg``: pieces
kept, not joined, shared with topics) and the transport's bounded send (``transport.
tcpros_service``: progress-driven, bounded by node shutdown, a vanished peer and
SEND_STALL_TIMEOUT), over socket pairs."""

from __future__ import annotations

import socket
import threading
import time

import numpy as np
import pytest

from minros.client import msg as client_msg
from minros.client import services
from minros.exceptions import TransportTerminated
from minros.transport import tcpros_service
from minros.wire import sockets, tcpros


def send_all(sock, data, stop=lambda: False, stall_timeout=None) -> None:
    tcpros_service.ServiceClientEnd(sock, "/s", stop, stall_timeout=stall_timeout).send_all(data)


def drain(sock: socket.socket, size: int, out: bytearray, pause_every: int = 0, pause: float = 0.0) -> None:
    while len(out) < size:
        chunk = sock.recv(65536)
        if not chunk:
            return
        if pause_every and (len(out) + len(chunk)) // pause_every != len(out) // pause_every:
            time.sleep(pause)  # a slow reader (the scenario, not synchronisation)
        out += chunk


def send_and_collect(parts, *, poll: float = 0.1, pause_every: int = 0, pause: float = 0.0) -> bytes:
    a, b = socket.socketpair()
    with a, b:
        a.settimeout(poll)
        b.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 65536)
        total = sum(memoryview(p).nbytes for p in parts) if isinstance(parts, list) else len(parts)
        out = bytearray()
        reader = threading.Thread(target=drain, args=(b, total, out, pause_every, pause))
        reader.start()
        send_all(a, parts)
        reader.join(20)
        assert not reader.is_alive()
        return bytes(out)


def test_a_small_message_is_one_joined_frame():
    from std_msgs.msg import String

    buff = client_msg._Parts(snapshot=False)
    String("hello").serialize(buff)
    assert buff.frame(b"") == tcpros.encode_frame(String("hello").serialize_to_bytes())
    assert client_msg.serialize_frame(String("hello"), snapshot=False) == buff.frame(b"")


def test_big_fields_are_kept_without_a_copy():
    from sensor_msgs.msg import Image

    data = bytes(range(256)) * 4096  # 1 MB
    msg = Image(height=1, width=len(data), encoding="mono8", step=len(data), data=data)
    for frame in (client_msg.serialize_frame(msg, b"\x01", snapshot=False),
                  _written(msg).frame(b"\x01")):
        assert any(part is data for part in frame)  # the field itself, not a copy
        assert len(frame) == 2  # ok byte, length and the small fields joined; then the data
        assert b"".join(bytes(p) for p in frame) == tcpros.encode_service_response(
            msg.serialize_to_bytes())


def _written(msg):
    buff = client_msg._Parts(snapshot=False)
    msg.serialize(buff)
    return buff


def test_numpy_and_mutable_buffers_are_kept_bytewise():
    buff = client_msg._Parts(snapshot=False)
    floats = np.arange(10000, dtype=np.float64)
    buff.write(floats)  # a non-byte format: cast so that a partial send can slice bytes
    buff.write(bytearray(b"xy"))
    buff.write(np.arange(12, dtype=np.uint8).reshape(3, 4)[:, ::2])  # not contiguous: copied
    frame = buff.frame(b"")
    expected = floats.tobytes() + b"xy" + bytes([0, 2, 4, 6, 8, 10])
    assert buff.size == len(expected)
    assert all(memoryview(p).format == "B" for p in frame)
    assert b"".join(bytes(p) for p in frame) == tcpros.frame_prefix(len(expected)) + expected
    snap = client_msg._Parts(snapshot=True)  # a topic's: what may wait in a queue is copied
    mutable = bytearray(b"z" * 5000)
    snap.write(mutable)
    mutable[:1] = b"!"
    assert snap.frame(b"").endswith(b"z" * 5000)  # small: one bytes object


def test_many_small_writes_stay_few_parts():
    buff = client_msg._Parts()
    for i in range(100000):
        buff.write(i.to_bytes(4, "little"))
    frame = buff.frame(b"P")
    assert len(frame) <= -(-400000 // client_msg._JOIN_LIMIT) + 1  # runs of _JOIN_LIMIT + prefix
    assert b"".join(frame) == b"P" + tcpros.frame_prefix(400000) + b"".join(
        i.to_bytes(4, "little") for i in range(100000))


def test_join_limit_and_serialization_are_written_once():
    assert not hasattr(services, "_JOIN_LIMIT") and not hasattr(services, "_Buffer")


def test_send_all_delivers_everything_in_order_to_a_slow_reader():
    big = bytes(range(256)) * 20000  # 5 MB
    parts = [b"head", big, memoryview(b"middle"), bytearray(b"x" * 70000), b"tail"]
    got = send_and_collect(parts, poll=0.05, pause_every=1 << 20, pause=0.15)
    assert got == b"".join(bytes(p) for p in parts)


def test_send_all_handles_more_buffers_than_one_sendmsg_takes():
    parts = [bytes([i % 256]) * 5000 for i in range(3 * sockets._MAX_IOV + 7)]
    assert send_and_collect(parts) == b"".join(parts)


def test_send_all_gives_up_on_a_stalled_peer(monkeypatch):
    monkeypatch.setattr(tcpros_service, "SEND_STALL_TIMEOUT", 0.5)
    a, b = socket.socketpair()
    with a, b:
        a.settimeout(0.1)
        start = time.monotonic()
        with pytest.raises(TransportTerminated, match=r"^peer took no data for 0\.5 s$"):
            send_all(a, [bytes(32 << 20)])  # more than the socket buffers hold
        assert 0.5 <= time.monotonic() - start < 3.0


def test_send_all_reports_a_vanished_peer():
    a, b = socket.socketpair()
    with a:
        a.settimeout(0.1)
        b.close()
        with pytest.raises(TransportTerminated, match=r"^unable to send data: .*(pipe|reset)"):
            send_all(a, [bytes(8 << 20)])


def test_send_all_stops_at_node_shutdown(monkeypatch):
    a, b = socket.socketpair()
    with a, b:
        a.settimeout(0.1)
        stop = threading.Event()
        threading.Timer(0.3, stop.set).start()
        start = time.monotonic()
        with pytest.raises(TransportTerminated, match="^node shutdown$"):
            send_all(a, [bytes(32 << 20)], stop=stop.is_set)
        assert time.monotonic() - start < 2.0  # well before SEND_STALL_TIMEOUT (60 s)


def test_send_all_of_nothing_returns():
    a, b = socket.socketpair()
    with a, b:
        a.settimeout(0.1)
        send_all(a, b"")
        send_all(a, [b"", bytearray()])
        send_all(a, [b"", b"ok"])
        assert b.recv(10) == b"ok"
