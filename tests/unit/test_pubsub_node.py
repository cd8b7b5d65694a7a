"""Pure parts of minros.node and minros.client: slave-API argument checks, frames, names
(the connections themselves: test_transport_tcpros.py)."""

from __future__ import annotations

import struct

import pytest

from minros import node
from minros.client import topics
from minros.exceptions import ROSSerializationException


@pytest.fixture
def api(monkeypatch):
    monkeypatch.delenv("ROS_MASTER_URI", raising=False)
    fake = node.Node(argv=["fake", "__name:=fake"])  # never started: no sockets
    fake.uri = "http://localhost:1234/"
    fake.connections.tcpros_address = lambda: ("localhost", 4321)
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


def test_request_topic_answers_the_first_offered_protocol_the_node_speaks(api):
    """The seam: the subscriber's order decides, among the protocols the node has handlers for."""
    from minros.transport.base import ProtocolHandler

    class Fake(ProtocolHandler):
        protocol = "FAKEROS"

        def answer(self, topic, offer):
            return ["FAKEROS", "fakehost", 7]

        def connect(self, answer, topic, buff_size, reuse_big, tcp_nodelay):
            raise AssertionError("not in this test")

    node_ = api._node
    node_.registries.publications["/t"] = object()
    assert api.requestTopic("/a", "/t", [["UDPROS"], ["TCPROS"]]) == [
        1, "ready on localhost:4321", ["TCPROS", "localhost", 4321]]
    node_.protocols.insert(0, Fake())
    assert api.requestTopic("/a", "/t", [["TCPROS"], ["FAKEROS"]])[2][0] == "TCPROS"
    assert api.requestTopic("/a", "/t", [["FAKEROS"], ["TCPROS"]]) == [
        1, "ready on fakehost:7", ["FAKEROS", "fakehost", 7]]
    assert api.requestTopic("/a", "/t", [["UDPROS"], "junk"]) == [
        0, "no supported protocol implementations", []]


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
    from minros.node.slave_api import xmlrpc_ints

    assert xmlrpc_ints([1, [2 ** 40, True], "x"]) == [1, [2 ** 31 - 1, True], "x"]


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

    with pytest.raises(ROSSerializationException):
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
