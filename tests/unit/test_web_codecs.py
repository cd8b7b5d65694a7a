"""minros web's pure parts: rosbridge JSON rules, CBOR, Foxglove frames, the outbox, rosapi,
video parameters and pixels, the imshow bridge's conversions. No sockets, no master."""

from __future__ import annotations

import base64
import json
import math
import re
import struct

import numpy as np
import pytest

from minros.client import imshow
from minros.msgs import Duration, Time, get_message_class, get_service_class
from minros.web import cbor, rosapi, video
from minros.web import foxglove_protocol as fp
from minros.web.convert import ConversionError, message_to_json, populate_message, request_values
from minros.web.outbox import Outbox


def now() -> Time:
    return Time(1700000000, 5)


# -- rosbridge JSON ------------------------------------------------------------------------

def test_json_rules_binary_time_nan():
    Image = get_message_class("sensor_msgs/Image")
    img = Image(height=1, width=3, encoding="mono8", step=3, data=b"\x00\x01\xff")
    img.header.stamp = Time(12, 34)
    values = message_to_json(img)
    assert values["data"] == base64.b64encode(b"\x00\x01\xff").decode()
    assert values["header"] == {"seq": 0, "stamp": {"secs": 12, "nsecs": 34}, "frame_id": ""}
    assert list(values) == list(Image.__slots__)  # definition order
    Imu = get_message_class("sensor_msgs/Imu")
    imu = Imu()
    imu.orientation.x = math.nan
    imu.linear_acceleration_covariance = [math.inf] + [0.0] * 8
    out = message_to_json(imu)
    assert out["orientation"]["x"] is None
    assert out["linear_acceleration_covariance"][0] is None
    json.dumps(out, allow_nan=False)  # valid JSON
    Marker = get_message_class("visualization_msgs/Marker")
    m = Marker()
    m.lifetime = Duration(3, 4)
    assert message_to_json(m)["lifetime"] == {"secs": 3, "nsecs": 4}


def test_json_populate_fills_header_time_and_accepts_base64_or_lists():
    Image = get_message_class("sensor_msgs/Image")
    msg = populate_message({"data": base64.b64encode(b"abc").decode(), "width": 3}, Image(), now)
    assert msg.data == b"abc" and msg.width == 3
    assert (msg.header.stamp.secs, msg.header.stamp.nsecs) == (1700000000, 5)  # header filled
    msg = populate_message({"data": [1, 2, 3], "header": {"frame_id": "cam"}}, Image(), now)
    assert msg.data == b"\x01\x02\x03" and msg.header.frame_id == "cam"
    assert msg.header.stamp.secs == 1700000000
    msg = populate_message({"header": {"stamp": {"secs": 7}}}, Image(), now)
    assert (msg.header.stamp.secs, msg.header.stamp.nsecs) == (7, 5)
    Twist = get_message_class("geometry_msgs/Twist")
    twist = populate_message({"linear": {"x": 1}}, Twist(), now)  # an int fills a float64
    assert twist.linear.x == 1
    Clock = get_message_class("rosgraph_msgs/Clock")
    assert populate_message({"clock": "now"}, Clock(), now).clock == now()


@pytest.mark.parametrize("values, text", [
    ({"linear": {"q": 1}}, "Message type geometry_msgs/Twist does not have a field linear.q"),
    ({"linear": {"x": "fast"}},
     "geometry_msgs/Twist message requires a float64 for field linear.x, but got a <class 'str'>"),
    ({"linear": 3}, "geometry_msgs/Twist message requires a geometry_msgs/Vector3 for field linear, "
                    "but got a <class 'int'>"),
    ({"linear": {"x": True}},
     "geometry_msgs/Twist message requires a float64 for field linear.x, but got a <class 'bool'>"),
])
def test_json_populate_errors_name_the_field(values, text):
    Twist = get_message_class("geometry_msgs/Twist")
    with pytest.raises(ConversionError) as err:
        populate_message(values, Twist(), now)
    assert str(err.value) == text


def test_json_populate_int_into_float_only_and_bad_base64():
    Int32 = get_message_class("std_msgs/Int32")
    with pytest.raises(ConversionError, match="requires a int32 for field data"):
        populate_message({"data": 1.5}, Int32(), now)
    with pytest.raises(ConversionError, match="Expected a JSON object for type std_msgs/Int32"):
        populate_message([1], Int32(), now)
    UInt8MultiArray = get_message_class("std_msgs/UInt8MultiArray")
    with pytest.raises(ConversionError, match="base64"):
        populate_message({"data": "!!notbase64"}, UInt8MultiArray(), now)


def test_service_args_as_list_or_dict():
    Req = get_service_class("turtlesim/Spawn")._request_class
    assert request_values([1.0, 2.0], Req()) == {"x": 1.0, "y": 2.0}
    assert request_values({"name": "t"}, Req()) == {"name": "t"}
    assert request_values(None, Req()) == {}


# -- CBOR ----------------------------------------------------------------------------------

@pytest.mark.parametrize("value, encoded", [  # RFC 8949 appendix A
    (0, "00"), (23, "17"), (24, "1818"), (1000, "1903e8"), (1000000, "1a000f4240"),
    (-1, "20"), (-1000, "3903e7"), (1.1, "fb3ff199999999999a"), (False, "f4"), (True, "f5"),
    (None, "f6"), ("", "60"), ("IETF", "6449455446"), ("\u00fc", "62c3bc"), (b"\x01\x02", "420102"),
    ([1, [2, 3]], "8201820203"), ({"a": 1, "b": [2, 3]}, "a26161016162820203"),
    (18446744073709551615, "1bffffffffffffffff"),
])
def test_cbor_encoding_matches_rfc_examples(value, encoded):
    assert cbor.dumps(value).hex() == encoded


def test_cbor_values_use_typed_arrays():
    Float = get_message_class("std_msgs/Float32MultiArray")
    values = cbor.message_to_cbor_values(Float(data=[1.0, 2.5]))
    assert values["data"] == cbor.Tag(85, struct.pack("<2f", 1.0, 2.5))
    Image = get_message_class("sensor_msgs/Image")
    values = cbor.message_to_cbor_values(Image(data=b"xyz"))
    assert values["data"] == b"xyz" and values["header"]["stamp"] == {"secs": 0, "nsecs": 0}
    assert cbor.dumps(cbor.Tag(85, b"")).hex() == "d85540"


# -- Foxglove frames -----------------------------------------------------------------------

def test_foxglove_binary_frames_layout():
    frame = fp.message_data(7, 123456789, b"\x01\x02")
    assert frame == b"\x01" + struct.pack("<IQ", 7, 123456789) + b"\x01\x02"
    assert fp.time_frame(5) == b"\x02" + struct.pack("<Q", 5)
    assert fp.service_call_response(3, 4, "ros1", b"ok") == (
        b"\x03" + struct.pack("<III", 3, 4, 4) + b"ros1ok")
    msg = fp.parse_binary(b"\x01" + struct.pack("<I", 9) + b"payload")
    assert msg.channel_id == 9 and bytes(msg.payload) == b"payload"
    call = fp.parse_binary(b"\x02" + struct.pack("<III", 1, 2, 4) + b"ros1" + b"req")
    assert (call.service_id, call.call_id, call.encoding, bytes(call.payload)) == (1, 2, "ros1", b"req")


@pytest.mark.parametrize("data, text", [
    (b"", "empty binary message"),
    (b"\x01\x00", "shorter than its 5-byte header"),
    (b"\x02" + b"\x00" * 8, "shorter than its 13-byte header"),
    (b"\x02" + struct.pack("<III", 1, 2, 99) + b"ros1", "encoding length past the end"),
    (b"\x09abc", "Unrecognized client binary opcode 9"),
])
def test_foxglove_bad_binary_frames(data, text):
    with pytest.raises(fp.ProtocolError, match=text):
        fp.parse_binary(data)


def test_foxglove_text_and_graph_update():
    with pytest.raises(fp.ProtocolError, match="Invalid JSON"):
        fp.parse_text("{nope")
    with pytest.raises(fp.ProtocolError, match="string 'op'"):
        fp.parse_text("[1]")
    old = ({"/a": {"/n1"}}, {}, {"/s": {"/n1"}})
    new = ({"/a": {"/n1", "/n2"}, "/b": {"/n3"}}, {"/a": {"/n4"}}, {})
    update = fp.connection_graph_update(old, new)
    assert update["publishedTopics"] == [{"name": "/a", "publisherIds": ["/n1", "/n2"]},
                                         {"name": "/b", "publisherIds": ["/n3"]}]
    assert update["subscribedTopics"] == [{"name": "/a", "subscriberIds": ["/n4"]}]
    assert update["removedServices"] == ["/s"] and update["removedTopics"] == []
    assert fp.connection_graph_update(new, new) is None
    assert fp.parameter("/p", 1.5) == {"name": "/p", "value": 1.5, "type": "float64"}
    assert fp.parameter("/b", b"AB") == {"name": "/b", "value": "QUI=", "type": "byte_array"}
    assert fp.parameter_from_client({"name": "/b", "value": "QUI=", "type": "byte_array"}) == ("/b", b"AB", False)
    assert fp.parameter_from_client({"name": "/gone"}) == ("/gone", None, True)


# -- the outbox ----------------------------------------------------------------------------

class FakeClock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def test_outbox_keeps_the_latest_and_drops_the_oldest():
    box = Outbox()
    box.open_slot("s", lambda x: x, maxlen=3)
    for i in range(10):
        box.put("s", i, 1)
    got = [box.get(timeout=0)[1] for _ in range(3)]
    assert got == [7, 8, 9]
    assert box.get(timeout=0) is None
    assert box.stats()["s"] == (0, 3, 7)


def test_outbox_byte_bound_keeps_at_least_one():
    box = Outbox()
    box.open_slot("img", lambda x: x, maxlen=100, max_bytes=10)
    for i in range(5):
        box.put("img", i, 6)
    assert [box.get(timeout=0)[1] for _ in range(1)] == [4]
    assert box.get(timeout=0) is None


def test_outbox_control_first_then_round_robin_and_overflow():
    box = Outbox(max_control_items=2)
    box.open_slot("a", str)
    box.open_slot("b", str)
    box.put("a", 1)
    box.put("b", 2)
    assert box.put_control("c1") and box.put_control("c2")
    assert not box.put_control("c3")  # the client owes too much: caller closes it
    assert [box.get(timeout=0)[1] for _ in range(4)] == ["c1", "c2", 1, 2]
    box.put("x", 5)  # no such slot: dropped
    assert box.get(timeout=0) is None
    box.close()
    assert box.get() is None


def test_outbox_throttle_interval():
    clock = FakeClock()
    box = Outbox(clock=clock)
    box.open_slot("t", str, maxlen=1, min_interval=0.5)
    box.put("t", 1)
    assert box.get(timeout=0)[1] == 1
    box.put("t", 2)
    box.put("t", 3)
    assert box.get(timeout=0) is None  # not due yet
    clock.t += 0.5
    assert box.get(timeout=0)[1] == 3  # the latest, once due


# -- rosapi --------------------------------------------------------------------------------

class Backend:
    def __init__(self) -> None:
        self.params = {"/a": 1}

    def read_graph(self) -> rosapi.Graph:
        return rosapi.Graph(topic_types={"/chatter": "std_msgs/String", "/x/goal": "a/Goal"},
                            publishers={"/chatter": ["/talker"]},
                            subscribers={"/chatter": ["/listener"], "/lonely": ["/l"]},
                            services={"/add": ["/server"]})

    def service_type(self, name: str) -> str:
        return {"/add": "rospy_tutorials/AddTwoInts"}[name]

    def service_uri(self, name: str) -> str:
        return "rosrpc://robot.local:4567"

    def get_param(self, name, default):
        return self.params.get(name, default)

    def set_param(self, name, value):
        self.params[name] = value

    def has_param(self, name):
        return name in self.params

    def delete_param(self, name):
        del self.params[name]

    def search_param(self, name):
        return None

    def get_param_names(self):
        return sorted(self.params)

    def now(self):
        return Time(5, 6)


def call(api: rosapi.Rosapi, service: str, /, **fields) -> dict:
    srv = api.service_class(service)
    return message_to_json(api.handle(service, srv._request_class(**fields)))


def test_rosapi_graph_services():
    api = rosapi.Rosapi(Backend())
    assert call(api, "/rosapi/topics") == {"topics": ["/chatter", "/lonely"],
                                           "types": ["std_msgs/String", ""]}
    assert call(api, "/rosapi/topic_type", topic="/chatter") == {"type": "std_msgs/String"}
    assert call(api, "/rosapi/nodes") == {"nodes": ["/l", "/listener", "/server", "/talker"]}
    assert call(api, "/rosapi/node_details", node="/talker") == {
        "subscribing": [], "publishing": ["/chatter"], "services": []}
    assert call(api, "/rosapi/services_for_type", type="rospy_tutorials/AddTwoInts") == {"services": ["/add"]}
    assert call(api, "/rosapi/service_host", service="/add") == {"host": "robot.local"}
    assert call(api, "/rosapi/get_time") == {"time": {"secs": 5, "nsecs": 6}}
    hidden = rosapi.Rosapi(Backend(), topics_glob=["/lon*"])
    assert call(hidden, "/rosapi/topics")["topics"] == ["/lonely"]
    assert call(hidden, "/rosapi/topic_type", topic="/chatter") == {"type": ""}


def test_rosapi_params_are_json_text():
    backend = Backend()
    api = rosapi.Rosapi(backend)
    call(api, "/rosapi/set_param", name="/b", value='{"k": [1, 2]}')
    assert backend.params["/b"] == {"k": [1, 2]}
    assert call(api, "/rosapi/get_param", name="/b") == {"value": '{"k": [1, 2]}'}
    assert call(api, "/rosapi/get_param", name="/missing", default="3") == {"value": "3"}
    assert call(api, "/rosapi/get_param", name="/missing") == {"value": "null"}
    with pytest.raises(rosapi.RosapiError, match="JSON-formatted string"):
        call(api, "/rosapi/set_param", name="/b", value="not json")
    call(api, "/rosapi/delete_param", name="/b")
    assert call(api, "/rosapi/has_param", name="/b") == {"exists": False}


def test_rosapi_typedefs():
    api = rosapi.Rosapi(Backend())
    defs = call(api, "/rosapi/message_details", type="visualization_msgs/Marker")["typedefs"]
    marker = defs[0]
    assert marker["type"] == "visualization_msgs/Marker"
    assert marker["fieldtypes"][:2] == ["std_msgs/Header", "string"]
    assert marker["fieldarraylen"][marker["fieldnames"].index("points")] == 0
    assert marker["examples"][marker["fieldnames"].index("ns")] == ""
    assert marker["examples"][marker["fieldnames"].index("id")] == "0"
    assert marker["constnames"] == sorted(marker["constnames"]) and "ARROW" in marker["constnames"]
    assert marker["constvalues"][marker["constnames"].index("ARROW")] == "0"
    assert [d["type"] for d in defs].count("std_msgs/Header") == 1
    assert {"type": "time", "fieldnames": ["secs", "nsecs"], "fieldtypes": ["int32", "int32"],
            "fieldarraylen": [-1, -1], "examples": ["0", "0"], "constnames": [],
            "constvalues": []} in defs
    req = call(api, "/rosapi/service_request_details", type="turtlesim/Spawn")["typedefs"]
    assert req[0]["type"] == "turtlesim/SpawnRequest" and req[0]["fieldnames"] == ["x", "y", "theta", "name"]
    assert rosapi.action_servers(["/a/cancel", "/a/feedback", "/a/goal", "/a/result", "/a/status",
                                  "/b/goal"]) == ["/a"]


def test_rosapi_definitions_are_rosbridges():
    """The bundled rosapi types, verbatim from rosbridge_suite 0.11.17: md5 sums as ROS computes
    them (Topics, GetParam, GetTime, MessageDetails, NodeDetails, TopicsAndRawTypes and TypeDef
    were checked against generated code published for rosapi)."""
    expected = {"Topics": "d966d98fc333fa1f3135af765eac1ba8", "GetParam": "e36fd90759dbac1c5159140a7fa8c644",
                "GetTime": "556a4fb76023a469987922359d08a844", "MessageDetails": "f9c88144f6f6bd888dd99d4e0411905d",
                "NodeDetails": "e1d0ced5ab8d5edb5fc09c98eb1d46f6",
                "TopicsAndRawTypes": "e1432466c8f64316723276ba07c59d12"}
    for name, md5 in expected.items():
        assert get_service_class(f"rosapi/{name}")._md5sum == md5
    assert get_message_class("rosapi/TypeDef")._md5sum == "80597571d79bbeef6c9c4d98f30116a0"
    for type_name, _method in rosapi.SERVICES.values():
        assert get_service_class(type_name)._type == type_name


# -- video ---------------------------------------------------------------------------------

def test_video_params():
    p = video.parse_params("topic=/cam&width=320&height=240&quality=50&invert")
    assert (p.topic, p.width, p.height, p.quality, p.invert) == ("/cam", 320, 240, 50, True)
    assert video.parse_params("topic=cam").topic == "/cam"
    for query, text in (("", "missing ?topic="), ("topic=/c&quality=0", "quality=0 is out of range"),
                        ("topic=/c&width=x", "width='x' is not an integer"),
                        ("topic=/c&type=vp8", "type='vp8' is not served here")):
        with pytest.raises(video.VideoError, match=re.escape(text)):
            video.parse_params(query)


@pytest.mark.parametrize("encoding, dtype, channels", [
    ("bgr8", np.uint8, 3), ("rgb8", np.uint8, 3), ("rgba8", np.uint8, 4), ("mono8", np.uint8, 1),
    ("mono16", np.uint16, 1), ("bgr16", np.uint16, 3), ("32FC1", np.float32, 1),
    ("16UC1", np.uint16, 1), ("8UC3", np.uint8, 3), ("bayer_rggb8", np.uint8, 1),
    ("64FC1", np.float64, 1), ("16SC1", np.int16, 1),
])
def test_every_encoding_becomes_bgr8(encoding, dtype, channels):
    from cv_bridge import CvBridge

    shape = (4, 6) if channels == 1 else (4, 6, channels)
    pixels = (np.arange(np.prod(shape)) % 200).reshape(shape).astype(dtype)
    msg = CvBridge().cv2_to_imgmsg(pixels, encoding)
    out = video.image_to_bgr8(msg)
    assert out.shape == (4, 6, 3) and out.dtype == np.uint8
    if encoding == "rgb8":
        assert (out[..., ::-1] == pixels).all()
    if encoding in ("32FC1", "16UC1"):
        assert out.max() == 255  # scaled to the maximum, as web_video_server shows depth


def test_jpeg_feed_encodes_once_per_frame_and_params():
    import cv2

    from cv_bridge import CvBridge

    class Tap:
        class state:
            class decoder:
                @staticmethod
                def class_for_header(header):
                    return get_message_class("sensor_msgs/Image")

    from minros.web.state import Incoming

    msg = CvBridge().cv2_to_imgmsg(np.full((8, 8, 3), 200, np.uint8), "bgr8")
    data = msg.serialize_to_bytes() if hasattr(msg, "serialize_to_bytes") else None
    feed = video.ImageFeed("/cam")
    feed.push(Incoming(Tap, data, {"type": "sensor_msgs/Image"}, 1))
    params = video.StreamParams("/cam", quality=80)
    seq, jpeg, _stamp = feed.jpeg(params)
    assert feed.jpeg(params)[1] is jpeg and feed.encoded == 1  # shared, not encoded again
    assert cv2.imdecode(np.frombuffer(jpeg, np.uint8), cv2.IMREAD_COLOR).shape == (8, 8, 3)
    feed.jpeg(video.StreamParams("/cam", width=4, height=4))
    assert feed.encoded == 2
    part = b"".join(video.stream_part(jpeg, 1.5))
    assert part.startswith(b"Content-type: image/jpeg\r\nX-Timestamp: 1.500000\r\n")
    assert part.endswith(b"\r\n--boundarydonotcross\r\n")


# -- imshow --------------------------------------------------------------------------------

def test_imshow_topic_names_and_pixels():
    assert imshow.topic_for("camera") == "/imshow/camera"
    assert imshow.topic_for("My Window!") == "/imshow/My_Window_"
    assert imshow.topic_for("3d view") == "/imshow/w3d_view"
    pixels, enc = imshow.displayable(np.full((2, 2), 0x1234, np.uint16))
    assert enc == "mono8" and pixels[0, 0] == 0x12  # 16-bit shown divided by 256
    pixels, enc = imshow.displayable(np.full((2, 2, 3), 0.5, np.float32))
    assert enc == "bgr8" and pixels[0, 0, 0] == 127  # float shown times 255
    assert imshow.displayable(np.zeros((2, 2, 4), np.uint8))[1] == "bgra8"


def test_imshow_patch_only_without_gui(monkeypatch):
    class HeadlessCv2:
        imshow = len  # a builtin, like OpenCV's own

        @staticmethod
        def getBuildInformation():  # noqa: N802
            return "\n  GUI:                           NONE\n"

    class GuiCv2(HeadlessCv2):
        imshow = len

        @staticmethod
        def getBuildInformation():  # noqa: N802
            return "\n  GUI:                           GTK3\n"

    headless, gui = HeadlessCv2(), GuiCv2()
    assert imshow.patch(gui) is False and gui.imshow is len
    monkeypatch.setenv("MINROS_IMSHOW", "off")
    assert imshow.patch(headless) is False
    monkeypatch.delenv("MINROS_IMSHOW")
    assert imshow.patch(headless) is True and headless.imshow is imshow.imshow
    assert imshow.patch(headless) is False  # not twice
