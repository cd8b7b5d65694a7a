"""Pure parts of minros.node and minros.client.topics: slave-API argument checks, frames, names."""

from __future__ import annotations

import struct

import pytest

from minros import node
from minros.client import topics


@pytest.fixture
def api(monkeypatch):
    monkeypatch.delenv("ROS_MASTER_URI", raising=False)
    fake = node.Node(argv=["fake", "__name:=fake"])  # never started: no sockets
    fake.uri = "http://localhost:1234/"
    fake.tcpros_address = lambda: ("localhost", 4321)
    return node.SlaveApi(fake)


def test_slave_api_arity_and_caller_id(api):
    assert api.getPid() == [-1, "missing required caller_id parameter", -1]
    assert api.getPid("/a", "b") == [-1, "Error: bad call arity", -1]
    assert api.getPid(3) == [-1, "caller_id must be a string", -1]
    assert api.getPid("/a")[0] == 1
    assert api.shutdown("/a")[:2] == [-1, "Error: bad call arity"]  # rospy wants the message too


def test_request_topic_validation(api):
    assert api.requestTopic("/a", "/no_such", [["TCPROS"]]) == [-1, "Not a publisher of [/no_such]", []]
    assert api.requestTopic("/a", "/t", "TCPROS")[0] == -1
    assert api.requestTopic("/a", "/t", [])[0] == -1
    assert api.requestTopic("/a", "bad name", [["TCPROS"]])[:2] == [
        -1, "ERROR: parameter [topic] contains illegal chars"]
    assert api.requestTopic("/a", "/", [["TCPROS"]])[0] == -1


def test_publisher_update_validation(api):
    assert api.publisherUpdate("/a", "/t", "http://x:1/") == [
        -1, "ERROR: param [publishers] must be a list", -1]
    assert api.publisherUpdate("/a", "/t", [1])[0] == -1
    assert api.publisherUpdate("/a", "/t", ["localhost:1"])[0] == -1
    assert api.publisherUpdate("/a", "/t", []) == [1, "", 0]


def test_param_update_needs_global_key(api):
    assert api.paramUpdate("/a", "rel", 1)[1] == (
        "ERROR: parameter [parameter_key] must be a globally referenced name")
    assert api.paramUpdate("/a", "/unknown", 1) == [-1, "not subscribed", 0]


def test_master_uri_and_bus_calls(api):
    assert api.getMasterUri("/a") == [1, "http://localhost:11311/", "http://localhost:11311/"]
    assert api.getBusInfo("/a") == [1, "bus info", []]
    assert api.getBusStats("/a") == [1, "", [[], [], []]]


def test_counters_saturate_for_xmlrpc():
    assert node._xmlrpc_ints([1, [2 ** 40, True], "x"]) == [1, [2 ** 31 - 1, True], "x"]


def test_pre_init_names_use_namespace_and_remaps():
    fresh = node.Node(argv=["prog", "chatter:=/remapped", "__name:=x"])
    assert fresh.resolve_name_without_node_name("chatter") == "/remapped"
    assert fresh.resolve_name_without_node_name("other") == "/other"
    with pytest.raises(ValueError, match="~name topics cannot be created before init_node"):
        fresh.resolve_name_without_node_name("~private")


def test_serialize_frame_small_and_large():
    from std_msgs.msg import String, UInt8MultiArray

    frame = topics.serialize_frame(String("hi"))
    assert frame == struct.pack("<I", 6) + struct.pack("<I", 2) + b"hi"
    big = UInt8MultiArray(data=bytes(200_000))
    parts = topics.serialize_frame(big)
    assert isinstance(parts, tuple)
    joined = b"".join(parts)
    assert struct.unpack_from("<I", joined)[0] == len(joined) - 4
    assert joined[4:] == big.serialize_to_bytes()


def test_serialize_frame_reports_the_bad_field():
    from std_msgs.msg import Int32

    with pytest.raises(topics.ROSSerializationException):
        topics.serialize_frame(Int32(data="not a number"))


def test_publish_argument_forms():
    from std_msgs.msg import ColorRGBA

    msg = ColorRGBA(1, 2, 3, 4)
    assert topics.args_kwds_to_message(ColorRGBA, (msg,), {}) is msg
    assert topics.args_kwds_to_message(ColorRGBA, (1, 2, 3, 4), {}) == msg
    assert topics.args_kwds_to_message(ColorRGBA, (), {"r": 1, "g": 2, "b": 3, "a": 4}) == msg
    with pytest.raises(TypeError):
        topics.args_kwds_to_message(ColorRGBA, (1,), {"g": 2})


def test_any_msg_round_trip():
    raw = topics.AnyMsg().deserialize(b"\x02\x00\x00\x00hi")
    assert raw._buff == b"\x02\x00\x00\x00hi"
    assert topics.serialize_frame(raw) == b"\x06\x00\x00\x00\x02\x00\x00\x00hi"


class _Impl:
    resolved_name = "/t"

    def __init__(self):
        self.removed = []

    def _remove_connection(self, conn):
        self.removed.append(conn)


@pytest.mark.parametrize("queue_size", [None, 0])
def test_connection_stream_is_byte_exact_under_backpressure(queue_size):
    """Frames of all sizes through a tiny socket buffer: partial sends are resumed in order
    (synchronous and queued modes; queue_size=0 is unbounded, so nothing may be dropped)."""
    import socket
    import threading

    from minros.wire import tcpros

    a, b = socket.socketpair()
    a.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)
    conn = topics._PubConnection(_Impl(), a, ("local", 0), {"callerid": "/s"}, queue_size)
    payloads = [bytes([i % 256]) * size for i, size in enumerate([10, 70_000, 5, 200_000, 3000, 1])]
    frames = [topics.serialize_frame(topics.AnyMsg(p)) for p in payloads]
    received: list = []

    def read():
        reader = tcpros.FrameReader()
        while len(received) < len(payloads):
            chunk = b.recv(1000)
            if not chunk:
                break
            received.extend(bytes(f) for f in reader.feed(chunk))

    thread = threading.Thread(target=read)
    thread.start()
    for frame in frames:
        conn.write(frame)
    thread.join(10)
    conn.close()
    b.close()
    assert received == payloads


def test_close_interrupts_a_synchronous_send_to_a_slow_reader():
    """queue_size=None holds the connection while a reader keeps taking bytes; unregister and
    shutdown must still close it at once (the trickling reader never lets the send finish)."""
    import socket
    import threading
    import time

    a, b = socket.socketpair()
    conn = topics._PubConnection(_Impl(), a, ("local", 0), {"callerid": "/s"}, None)
    stop = threading.Event()

    def trickle():
        while not stop.wait(0.05):
            try:
                b.recv(4096)
            except OSError:
                return

    reader = threading.Thread(target=trickle, daemon=True)
    reader.start()
    sender = threading.Thread(target=conn.write, args=(bytes(8 << 20),), daemon=True)
    sender.start()
    try:
        deadline = time.monotonic() + 5
        while conn.stat_bytes == 0 and time.monotonic() < deadline:  # the send is under way
            time.sleep(0.01)
        assert conn.stat_bytes > 0 and sender.is_alive()
        closer = threading.Thread(target=conn.close, daemon=True)
        closer.start()
        closer.join(3)
        assert not closer.is_alive(), "close() waited for the slow reader"
        sender.join(3)
        assert not sender.is_alive() and conn.done
    finally:
        stop.set()
        b.close()


def test_hand_written_genpy_style_class_is_published_through_its_serialize():
    """A class written by hand against genpy.Message (only serialize/deserialize defined), as
    rospy accepts: the frame is what its serialize() writes."""
    import genpy

    class Hand(genpy.Message):
        __slots__ = ["data"]
        _type = "std_msgs/String"
        _md5sum = "992ce8a1687cec8c8bd883ec73ca41d1"
        _has_header = False
        _full_text = "string data\n"
        _slot_types = ["string"]

        def __init__(self, data=""):
            self.data = data

        def serialize(self, buff):
            raw = self.data.encode()
            buff.write(struct.pack("<I", len(raw)))
            buff.write(raw)

    assert topics.serialize_frame(Hand("hi")) == struct.pack("<II", 6, 2) + b"hi"
