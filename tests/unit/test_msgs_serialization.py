"""Wire format of every builtin type and array form, bad data, bad values, numpy_msg views."""

from __future__ import annotations

import io
import pickle
import struct

import numpy as np
import pytest

from minros.exceptions import DeserializationError, SerializationError
from minros.msgs import Duration, MsgContext, Time, get_message_class, numpy_msg
from minros.msgs.spec import parse_msg

ALL_TYPES = """\
bool b
int8 i8
byte by
uint8 u8
char ch
int16 i16
uint16 u16
int32 i32
uint32 u32
int64 i64
uint64 u64
float32 f32
float64 f64
string s
time t
duration d
uint8[] bytes_var
char[3] chars_fixed
int16[] shorts
float64[2] doubles
string[] strings
string[2] strings_fixed
bool[] bools
time[] times
Inner inner
Inner[] inners
Inner[2] inners_fixed
"""


@pytest.fixture(scope="module")
def ctx() -> MsgContext:
    context = MsgContext(search=False)
    context.add_spec(parse_msg("int32 a\nstring b", "pkg/Inner"))
    context.add_spec(parse_msg(ALL_TYPES, "pkg/All"))
    return context


def _wire(cls, msg) -> bytes:
    buf = io.BytesIO()
    msg.serialize(buf)
    return buf.getvalue()


def test_every_builtin_and_array_form(ctx: MsgContext) -> None:
    All = ctx.get_class("pkg/All")
    Inner = ctx.get_class("pkg/Inner")
    msg = All(
        b=True, i8=-2, by=-3, u8=250, ch=255, i16=-300, u16=65000, i32=-70000, u32=4000000000,
        i64=-(2 ** 40), u64=2 ** 63, f32=1.5, f64=-2.25, s="é", t=Time(1, 2), d=Duration(-1, 5),
        bytes_var=b"\x00\xff", chars_fixed=b"abc", shorts=[1, -1], doubles=[0.5, 1.0],
        strings=["a", ""], strings_fixed=["x", "yz"], bools=[True, False], times=[Time(3, 4)],
        inner=Inner(1, "q"), inners=[Inner(2, "")], inners_fixed=[Inner(3, "r"), Inner(4, "s")],
    )
    expected = b"".join([
        struct.pack("<?bbBBhHiIqQfd", True, -2, -3, 250, 255, -300, 65000, -70000, 4000000000,
                    -(2 ** 40), 2 ** 63, 1.5, -2.25),
        struct.pack("<I", 2), "é".encode(),
        struct.pack("<IIii", 1, 2, -1, 5),
        struct.pack("<I", 2), b"\x00\xff",
        b"abc",                                   # fixed uint8/char array: no count
        struct.pack("<Ihh", 2, 1, -1),
        struct.pack("<dd", 0.5, 1.0),             # fixed array: no count
        struct.pack("<II1sI", 2, 1, b"a", 0),
        struct.pack("<I1sI2s", 1, b"x", 2, b"yz"),
        struct.pack("<IBB", 2, 1, 0),
        struct.pack("<III", 1, 3, 4),
        struct.pack("<iI1s", 1, 1, b"q"),
        struct.pack("<IiI", 1, 2, 0),
        struct.pack("<iI1siI1s", 3, 1, b"r", 4, 1, b"s"),
    ])
    assert _wire(All, msg) == expected
    back = All().deserialize(expected)
    assert back == msg
    assert back.bytes_var == b"\x00\xff" and type(back.bytes_var) is bytes
    assert type(back.chars_fixed) is bytes and back.bools == [True, False]
    assert back.d == Duration(-1, 5) and back.d.secs == -1 and back.d.nsecs == 5
    assert isinstance(back.t, Time) and isinstance(back.d, Duration)


def test_defaults_match_genpy(ctx: MsgContext) -> None:
    msg = ctx.get_class("pkg/All")()
    assert (msg.b, msg.i8, msg.f32, msg.s, msg.t, msg.d) == (False, 0, 0.0, "", Time(), Duration())
    assert msg.bytes_var == b"" and msg.chars_fixed == b"\x00\x00\x00"
    assert msg.doubles == [0.0, 0.0] and msg.strings_fixed == ["", ""] and msg.shorts == []
    assert msg.inners_fixed[0] is not msg.inners_fixed[1]
    assert msg.inner.a == 0 and msg.inner.b == ""


def test_constructor_rules() -> None:
    from std_msgs.msg import ColorRGBA, Header

    assert ColorRGBA(1.0, 0.5, 0.25, 1.0).g == 0.5
    c = ColorRGBA(r=1.0, a=None)
    assert (c.r, c.g, c.a) == (1.0, 0.0, 0.0)
    with pytest.raises(TypeError):
        ColorRGBA(1.0, 2.0)
    with pytest.raises(TypeError):
        ColorRGBA(1.0, 2.0, 3.0, 4.0, r=1.0)
    with pytest.raises(AttributeError):
        ColorRGBA(nope=1)
    h = Header(stamp=None)
    assert h.stamp == Time() and h.seq == 0
    with pytest.raises(AttributeError):
        h.not_a_field = 1  # __slots__: no stray attributes


def test_decode_errors_are_replaced() -> None:
    from std_msgs.msg import String

    assert String().deserialize(b"\x02\x00\x00\x00\xff\xfe").data == "\ufffd\ufffd"


def test_bool_reads_any_nonzero_byte_as_true() -> None:
    from std_msgs.msg import Bool

    assert Bool().deserialize(b"\x02").data is True
    assert Bool().deserialize(b"\x00").data is False


def test_time_canonicalised_on_read() -> None:
    from std_msgs.msg import Duration as DurationMsg
    from std_msgs.msg import Time as TimeMsg

    t = TimeMsg().deserialize(struct.pack("<II", 1, 1500000000)).data
    assert (t.secs, t.nsecs) == (2, 500000000)
    d = DurationMsg().deserialize(struct.pack("<ii", 1, -1)).data
    assert (d.secs, d.nsecs) == (0, 999999999)


def test_equality_str_and_pickle() -> None:
    from geometry_msgs.msg import Point, PoseStamped
    from std_msgs.msg import Float32MultiArray

    a = PoseStamped()
    a.pose.position = Point(1.0, 2.0, 3.0)
    b = pickle.loads(pickle.dumps(a))
    assert a == b and type(b) is PoseStamped
    b.pose.position.z = 4.0
    assert a != b
    assert Float32MultiArray(data=[1.0]) == Float32MultiArray(data=(1.0,))
    assert str(Point(1.0, 2.0, 3.5)) == "x: 1.0\ny: 2.0\nz: 3.5"
    text = str(a)
    assert text.startswith("header: \n  seq: 0\n  stamp: \n    secs: 0\n    nsecs:         0\n"
                           "  frame_id: ''\npose: \n  position: \n    x: 1.0")


# -- bad data -----------------------------------------------------------------------------------

def test_truncated_data() -> None:
    from geometry_msgs.msg import PoseStamped
    from std_msgs.msg import Header, String

    with pytest.raises(DeserializationError, match="std_msgs/String"):
        String().deserialize(b"\x05\x00\x00\x00ab")
    with pytest.raises(DeserializationError, match="truncated"):
        Header().deserialize(b"\x01\x00\x00\x00\x02\x00")
    with pytest.raises(DeserializationError):
        String().deserialize(b"")
    data = PoseStamped().serialize_to_bytes()
    for cut in range(len(data)):
        with pytest.raises(DeserializationError):
            PoseStamped().deserialize(data[:cut])


def test_padded_data() -> None:
    from std_msgs.msg import String

    with pytest.raises(DeserializationError, match="1 unexpected bytes"):
        String().deserialize(b"\x01\x00\x00\x00ab")


@pytest.mark.parametrize("type_name, prefix", [
    ("std_msgs/Float64MultiArray", struct.pack("<II", 0, 0)),     # layout: no dims, offset
    ("std_msgs/UInt8MultiArray", struct.pack("<II", 0, 0)),
    ("rosgraph_msgs/Log", b""),
    ("sensor_msgs/PointCloud2", b""),
    ("visualization_msgs/MarkerArray", b""),
    ("std_msgs/String", b""),
])
def test_lying_length_is_rejected_before_allocation(type_name: str, prefix: bytes) -> None:
    cls = get_message_class(type_name)
    if not prefix:
        # a valid message whose first length/count field we then corrupt
        valid = cls().serialize_to_bytes()
        data = bytearray(valid)
        # find the first uint32 that is a length (the value 0 of an empty string/array)
        first = _first_count_offset(cls)
        data[first:first + 4] = b"\xff\xff\xff\xff"
        payload = bytes(data)
    else:
        payload = prefix + b"\xff\xff\xff\xff" + b"\x00" * 8
    with pytest.raises(DeserializationError) as info:
        cls().deserialize(payload)
    assert "remain" in str(info.value) or "truncated" in str(info.value)


def _first_count_offset(cls) -> int:
    """Offset of the first variable-length prefix in a default instance of ``cls``."""
    sizes = {"std_msgs/Header": 12, "rosgraph_msgs/Log": 12, "sensor_msgs/PointCloud2": 12,
             "visualization_msgs/MarkerArray": 0, "std_msgs/String": 0}
    return sizes[cls._type]


def test_array_of_empty_messages_has_a_bound(monkeypatch) -> None:
    ctx = MsgContext(search=False)
    ctx.add_spec(parse_msg("", "pkg/Nothing"))
    ctx.add_spec(parse_msg("Nothing[] many", "pkg/Many"))
    Many = ctx.get_class("pkg/Many")
    assert len(Many().deserialize(struct.pack("<I", 1000)).many) == 1000
    with pytest.raises(DeserializationError):
        Many().deserialize(struct.pack("<I", 0xFFFFFFFF))


def test_memoryview_and_bytearray_input() -> None:
    from std_msgs.msg import String

    data = String("abc").serialize_to_bytes()
    assert String().deserialize(memoryview(data)).data == "abc"
    assert String().deserialize(bytearray(data)).data == "abc"
    big = b"xx" + data + b"yy"
    assert String().deserialize(memoryview(big)[2:-2]).data == "abc"


# -- bad values ------------------------------------------------------------------------------

@pytest.mark.parametrize("type_name, setup, field", [
    ("std_msgs/String", lambda m: setattr(m, "data", 5), "data"),
    ("std_msgs/Header", lambda m: setattr(m, "seq", "a"), "seq"),
    ("std_msgs/Header", lambda m: setattr(m, "frame_id", None), "frame_id"),
    ("std_msgs/Header", lambda m: setattr(m, "stamp", 1.5), "stamp"),
    ("std_msgs/UInt8", lambda m: setattr(m, "data", 256), "data"),
    ("std_msgs/Int8", lambda m: setattr(m, "data", -129), "data"),
    ("std_msgs/Float64", lambda m: setattr(m, "data", "x"), "data"),
    ("geometry_msgs/PoseStamped", lambda m: setattr(m.pose.position, "x", "1"), "pose.position.x"),
    ("geometry_msgs/PoseStamped", lambda m: setattr(m.header, "seq", -1), "header.seq"),
    ("geometry_msgs/PoseWithCovariance", lambda m: setattr(m, "covariance", [0.0] * 35),
     "covariance"),
    ("std_msgs/Float32MultiArray", lambda m: setattr(m, "data", [1.0, "a"]), "data[]"),
    ("std_msgs/UInt8MultiArray", lambda m: setattr(m, "data", [1, 300]), "data[]"),
    ("visualization_msgs/MarkerArray", lambda m: setattr(m, "markers", [5]), "markers[]"),
    ("sensor_msgs/CameraInfo", lambda m: setattr(m, "K", [0.0] * 8), "K"),
    ("rosgraph_msgs/Log", lambda m: setattr(m, "topics", ["a", 3]), "topics[]"),
    ("std_msgs/String", lambda m: setattr(m, "data", "\ud800"), "data"),
])
def test_wrong_value_names_the_field(type_name, setup, field) -> None:
    msg = get_message_class(type_name)()
    setup(msg)
    with pytest.raises(SerializationError) as info:
        msg.serialize(io.BytesIO())
    # genpy's texts: check_type names the field (array elements as "name[]")
    assert f"field {field} " in str(info.value)


def test_bytes_and_lists_accepted_for_uint8_arrays() -> None:
    from std_msgs.msg import UInt8MultiArray

    a = UInt8MultiArray(data=[1, 2, 3]).serialize_to_bytes()
    b = UInt8MultiArray(data=b"\x01\x02\x03").serialize_to_bytes()
    c = UInt8MultiArray(data=bytearray(b"\x01\x02\x03")).serialize_to_bytes()
    d = UInt8MultiArray(data=np.array([1, 2, 3], dtype=np.uint8)).serialize_to_bytes()
    e = UInt8MultiArray(data=np.array([1, 2, 3])).serialize_to_bytes()  # int64 values, converted
    f = UInt8MultiArray(data=np.arange(1, 7, dtype=np.uint8)[::2]).serialize_to_bytes()  # strided
    g = UInt8MultiArray(data=(1, 2, 3)).serialize_to_bytes()
    assert a == b == c == d == e == g
    assert f.endswith(b"\x03\x00\x00\x00\x01\x03\x05")
    with pytest.raises(SerializationError, match="field data"):
        UInt8MultiArray(data=np.array([1, 256])).serialize_to_bytes()


def test_large_payload_written_without_join() -> None:
    from sensor_msgs.msg import Image

    payload = bytes(200000)
    img = Image(height=1, width=200000, encoding="mono8", step=200000, data=payload)

    class Gather:
        def __init__(self) -> None:
            self.parts: list = []

        def write(self, data) -> None:
            self.parts.append(data)

    out = Gather()
    img.serialize(out)
    assert any(part is payload for part in out.parts)
    assert b"".join(out.parts) == img.serialize_to_bytes()


# -- numpy_msg ---------------------------------------------------------------------------------

def test_numpy_msg_arrays_are_views_of_the_buffer() -> None:
    from sensor_msgs.msg import Image, PointCloud2
    from std_msgs.msg import Float64MultiArray

    data = Float64MultiArray(data=[1.0, 2.5, -3.0]).serialize_to_bytes()
    NF = numpy_msg(Float64MultiArray)
    msg = NF().deserialize(data)
    assert isinstance(msg.data, np.ndarray) and msg.data.dtype == np.dtype("<f8")
    assert msg.data.tolist() == [1.0, 2.5, -3.0]
    assert np.shares_memory(msg.data, np.frombuffer(data, dtype=np.uint8))
    assert numpy_msg(Float64MultiArray) is NF and NF._md5sum == Float64MultiArray._md5sum
    assert isinstance(msg, Float64MultiArray) and msg.__slots__ == Float64MultiArray.__slots__
    # writes back identical bytes
    assert msg.serialize_to_bytes() == data

    img = Image(height=2, width=3, encoding="mono8", step=3, data=bytes(range(6)))
    raw = bytearray(img.serialize_to_bytes())
    nimg = numpy_msg(Image)().deserialize(raw)
    assert np.shares_memory(nimg.data, np.frombuffer(raw, dtype=np.uint8))
    raw[-1] = 99  # a view: the change shows through
    assert nimg.data[-1] == 99

    cloud = numpy_msg(PointCloud2)().deserialize(PointCloud2(data=b"\x01" * 16).serialize_to_bytes())
    assert cloud.data.tobytes() == b"\x01" * 16


@pytest.mark.slow
def test_importing_messages_does_not_import_numpy() -> None:
    import subprocess
    import sys

    code = ("import sys; from std_msgs.msg import String; from geometry_msgs.msg import Twist; "
            "String('x').serialize_to_bytes(); Twist().serialize_to_bytes(); "
            "print('numpy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "False", out.stderr


def test_deserialize_numpy_and_instances_made_without_constructor() -> None:
    from geometry_msgs.msg import PoseStamped
    from std_msgs.msg import Float32MultiArray

    data = Float32MultiArray(data=[1.0, 2.0]).serialize_to_bytes()
    msg = Float32MultiArray().deserialize_numpy(data, np)
    assert isinstance(msg.data, np.ndarray) and msg.data.tolist() == [1.0, 2.0]
    assert numpy_msg(numpy_msg(Float32MultiArray)) is numpy_msg(Float32MultiArray)
    pose = PoseStamped()
    pose.header.frame_id = "f"
    bare = PoseStamped.__new__(PoseStamped)
    assert bare.deserialize(pose.serialize_to_bytes()) == pose


def test_deserialize_fills_embedded_messages_in_place() -> None:
    from geometry_msgs.msg import PoseStamped

    src = PoseStamped()
    src.pose.position.x = 3.0
    target = PoseStamped()
    position = target.pose.position
    target.deserialize(src.serialize_to_bytes())
    assert position is target.pose.position and position.x == 3.0  # as genpy
    target.pose.position = "not a point"  # a foreign value is replaced, not written into
    target.deserialize(src.serialize_to_bytes())
    assert target.pose.position.x == 3.0


def test_python_keyword_fields_get_an_underscore() -> None:
    ctx = MsgContext(search=False)
    ctx.add_spec(parse_msg("int32 from\nstring class\nint32 end\nint32 view", "pkg/Kw"))
    Kw = ctx.get_class("pkg/Kw")
    assert Kw.__slots__ == ["from_", "class_", "end", "view"]
    msg = Kw(from_=1, class_="c", end=2, view=3)
    assert Kw().deserialize(msg.serialize_to_bytes()) == msg


def test_generated_source_is_the_compiled_code() -> None:
    from minros.msgs import REGISTRY

    source = REGISTRY.source("sensor_msgs/Image")
    compile(source, "<test>", "exec")
    assert "class Image(_Message):" in source and "_S_B2I = _Struct('<B2I')" in source
    namespace: dict = {"_load": REGISTRY.get_class}
    exec(compile(source, "<test>", "exec"), namespace)
    assert namespace["Image"]._full_text == get_message_class("sensor_msgs/Image")._full_text


def test_numpy_values_for_numeric_arrays_are_checked() -> None:
    from geometry_msgs.msg import PoseWithCovariance
    from std_msgs.msg import Float32MultiArray, Int8MultiArray

    assert Float32MultiArray(data=np.array([1, 2])).serialize_to_bytes() == \
        Float32MultiArray(data=[1.0, 2.0]).serialize_to_bytes()
    cov = np.arange(36, dtype=np.float64)
    assert PoseWithCovariance(covariance=cov).serialize_to_bytes() == \
        PoseWithCovariance(covariance=list(cov)).serialize_to_bytes()
    for bad in (np.array([300]), np.array([1.5])):
        with pytest.raises(SerializationError, match="field data"):
            Int8MultiArray(data=bad).serialize_to_bytes()


def test_arrays_of_fixed_size_messages() -> None:
    from geometry_msgs.msg import Point, PoseArray

    ctx = MsgContext(search=False)
    ctx.add_spec(parse_msg("float32 x\nbool ok", "pkg/P"))
    ctx.add_spec(parse_msg("P[2] two\nP[] many", "pkg/Ps"))
    Ps, P = ctx.get_class("pkg/Ps"), ctx.get_class("pkg/P")
    msg = Ps(two=[P(1.0, True), P(2.0, False)], many=[P(3.0, True)])
    wire = msg.serialize_to_bytes()
    assert wire == struct.pack("<f?f?If?", 1.0, True, 2.0, False, 1, 3.0, True)
    assert Ps().deserialize(wire) == msg
    with pytest.raises(DeserializationError, match="two"):
        Ps().deserialize(wire[:5])
    poses = PoseArray(poses=[__import__("geometry_msgs.msg").msg.Pose(position=Point(1, 2, 3))] * 3)
    back = PoseArray().deserialize(poses.serialize_to_bytes())
    assert back == poses and back.poses[0] is not back.poses[1]
