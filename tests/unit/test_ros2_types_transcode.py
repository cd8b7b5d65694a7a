"""ROS 1 bytes <-> CDR bytes converters (minros.ros2.types.transcode): every type both sides
ship goes ROS 1 -> CDR -> ROS 1 and comes back equal but for the fields ROS 2 lacks, named
here; the CDR says what the ROS 1 message said; rosbags' converter writes the same bytes."""

from __future__ import annotations

import copy
import io
import struct
import tracemalloc

import pytest
from hypothesis import HealthCheck, given, settings

from minros.exceptions import DeserializationError, SerializationError
from minros.msgs import get_message_class
from minros.msgs.codegen import python_name
from minros.msgs.registry import list_types
from minros.msgs.testing import strategy_for
from minros.ros2.types import Mapper, registry
from minros.ros2.types.testing import plain, ros2_plain_of_ros1

MAPPER = Mapper("jazzy")

#: ROS 1 fields ROS 2 lacks, for every type both sides ship where they are more than a
#: top-level Header's seq (types with a Header lose exactly "header.seq"; the others nothing)
DROPPED = {
    "std_msgs/Header": ["seq"],
    "nav_msgs/Path": ["header.seq", "poses[].header.seq"],
    "rosgraph_msgs/Log": ["header.seq", "header.frame_id", "topics"],
    "stereo_msgs/DisparityImage": ["header.seq", "image.header.seq"],
    "tf/tfMessage": ["transforms[].header.seq"],
    "tf2_msgs/TFMessage": ["transforms[].header.seq"],
    "visualization_msgs/InteractiveMarker": ["header.seq", "controls[].markers[].header.seq"],
    "visualization_msgs/InteractiveMarkerControl": ["markers[].header.seq"],
    "visualization_msgs/InteractiveMarkerInit": [
        "markers[].header.seq", "markers[].controls[].markers[].header.seq"],
    "visualization_msgs/InteractiveMarkerUpdate": [
        "markers[].header.seq", "markers[].controls[].markers[].header.seq", "poses[].header.seq"],
    "visualization_msgs/MarkerArray": ["markers[].header.seq"],
}
MARKER_ONLY = ["texture_resource", "texture", "uv_coordinates", "mesh_file"]
#: ROS 2 members ROS 1 lacks (written with their defaults)
DEFAULTED = {
    "sensor_msgs/Range": ["variance"],
    "shape_msgs/SolidPrimitive": ["polygon"],
    "visualization_msgs/Marker": MARKER_ONLY,
    "visualization_msgs/MarkerArray": ["markers[]." + n for n in MARKER_ONLY],
    "visualization_msgs/InteractiveMarkerControl": ["markers[]." + n for n in MARKER_ONLY],
    "visualization_msgs/InteractiveMarker": ["controls[].markers[]." + n for n in MARKER_ONLY],
    "visualization_msgs/InteractiveMarkerInit": [
        "markers[].controls[].markers[]." + n for n in MARKER_ONLY],
    "visualization_msgs/InteractiveMarkerUpdate": [
        "markers[].controls[].markers[]." + n for n in MARKER_ONLY],
}


def both_sides() -> list:
    """ROS 1 types (minros's bundled definitions, Debian's) with a ROS 2 type of the bundled
    packages (not made by minros)."""
    packages = {n.split("/")[0] for n in registry("jazzy").type_names("msg")} | {"tf", "uuid_msgs"}
    out = []
    for package in sorted(packages):
        try:
            names = list_types(package)
        except LookupError:
            continue
        out += [t for t in names if not MAPPER.message(t).generated]
    return out


BOTH = both_sides()


def ros1_bytes(msg) -> bytes:
    buf = io.BytesIO()
    msg.serialize(buf)
    return buf.getvalue()


def reset(obj, path: str) -> None:
    """Set the ROS 1 field at ``path`` (``poses[].header.seq``) to its default."""
    head, _, rest = path.partition(".")
    if head.endswith("[]"):
        for item in getattr(obj, python_name(head[:-2])):
            reset(item, rest)
    elif rest:
        reset(getattr(obj, python_name(head)), rest)
    else:
        setattr(obj, python_name(head), getattr(type(obj)(), python_name(head)))


def test_the_table_of_dropped_and_defaulted_fields_is_complete():
    assert len(BOTH) > 110
    for t in BOTH:
        m = MAPPER.message(t)
        has_header = get_message_class(t)._has_header
        assert m.all_dropped() == DROPPED.get(t, ["header.seq"] if has_header else []), t
        assert m.all_defaulted() == DEFAULTED.get(t, []), t


@pytest.mark.fuzz
@pytest.mark.parametrize("ros1_type", BOTH)
def test_round_trip_and_values(ros1_type):
    m = MAPPER.message(ros1_type)
    transcoder = m.transcoder
    codec = MAPPER.ros2.codec(m.ros2_type)
    cls = get_message_class(ros1_type)

    @settings(max_examples=10, deadline=None, suppress_health_check=list(HealthCheck))
    @given(strategy_for(ros1_type, max_array=3))
    def check(msg):
        raw = ros1_bytes(msg)
        cdr = transcoder.ros1_to_cdr(raw)
        # the CDR holds what the ROS 1 message held, by the mapping
        assert plain(MAPPER.ros2, m.ros2_type, codec.deserialize(cdr)) == \
            ros2_plain_of_ros1(m, msg)
        # and comes back equal, but for the dropped fields (zero; a Header's seq is passed)
        seq = msg.header.seq if cls._has_header else 0
        expected = copy.deepcopy(msg)
        for path in m.all_dropped():
            if path != "header.seq":
                reset(expected, path)
        assert transcoder.cdr_to_ros1(cdr, seq=seq) == ros1_bytes(expected)
        # our CDR codec writes the same bytes the converter did
        assert codec.serialize(codec.deserialize(cdr)) == cdr

    check()


@pytest.mark.fuzz
def test_bytes_equal_rosbags_converters():
    """rosbags' ros1_to_cdr/cdr_to_ros1 (same layout on both sides, Header's seq dropped) give
    the same bytes as ours for the types whose ROS 2 members all come from ROS 1."""
    from rosbags.typesys import Stores, get_typestore

    from minros.msgs.testing import strategy_for as ros1_strategy
    from minros.ros2.types.testing import samples

    store = get_typestore(Stores.ROS2_JAZZY)
    compared = 0
    for t in BOTH:
        m = MAPPER.message(t)
        if m.all_defaulted() or m.ros2_type not in store.types or any(
                not p.endswith("header.seq") and p != "seq" for p in m.all_dropped()):
            continue
        compared += 1
        for msg in samples(ros1_strategy(t), 2):
            raw = ros1_bytes(msg)
            ours = m.transcoder.ros1_to_cdr(raw)
            assert ours == bytes(store.ros1_to_cdr(raw, m.ros2_type)), t
            assert m.transcoder.cdr_to_ros1(ours) == bytes(store.cdr_to_ros1(ours, m.ros2_type))
    assert compared > 90


def test_header_seq_is_what_the_caller_counts():
    t = MAPPER.message("nav_msgs/Path").transcoder
    path = get_message_class("nav_msgs/Path")()
    path.header.seq, path.header.frame_id = 41, "map"
    pose = get_message_class("geometry_msgs/PoseStamped")()
    pose.header.seq = 9
    path.poses = [pose]
    back = get_message_class("nav_msgs/Path")().deserialize(t.cdr_to_ros1(
        t.ros1_to_cdr(ros1_bytes(path)), seq=42))
    assert back.header.seq == 42 and back.poses[0].header.seq == 0
    assert t.has_header and not MAPPER.message("std_msgs/String").transcoder.has_header


def test_time_is_carried_bit_for_bit():
    t = MAPPER.message("rosgraph_msgs/Clock").transcoder
    clock = get_message_class("rosgraph_msgs/Clock")()
    clock.clock.secs, clock.clock.nsecs = 2 ** 32 - 1, 999_999_999  # 2106
    cdr = t.ros1_to_cdr(ros1_bytes(clock))
    ros2 = registry().codec("rosgraph_msgs/msg/Clock").deserialize(cdr)
    assert (ros2.clock.sec, ros2.clock.nanosec) == (-1, 999_999_999)
    assert t.cdr_to_ros1(cdr) == ros1_bytes(clock)
    duration = MAPPER.message("std_msgs/Duration").transcoder
    d = get_message_class("std_msgs/Duration")()
    d.data.secs, d.data.nsecs = -5, 3
    assert duration.ros1_to_cdr(ros1_bytes(d)).hex() == "00010000" "fbffffff" "03000000"


def test_rosout_log_by_the_rule():
    log = get_message_class("rosgraph_msgs/Log")()
    log.header.seq, log.header.stamp.secs, log.header.frame_id = 3, 10, "ignored"
    log.level, log.name, log.msg, log.line, log.topics = 2, "/talker", "hello", 7, ["/chatter"]
    m = MAPPER.message("rosgraph_msgs/Log")
    ros2 = MAPPER.ros2.codec("rcl_interfaces/msg/Log").deserialize(
        m.transcoder.ros1_to_cdr(ros1_bytes(log)))
    assert (ros2.stamp.sec, ros2.level, ros2.name, ros2.msg, ros2.line) == \
        (10, 2, "/talker", "hello", 7)  # levels copied as they are, as ros1_bridge does


def test_defaults_and_bounds_going_to_ros2():
    rng = get_message_class("sensor_msgs/Range")()
    rng.range = 1.5
    cdr = MAPPER.message("sensor_msgs/Range").transcoder.ros1_to_cdr(ros1_bytes(rng))
    assert MAPPER.ros2.codec("sensor_msgs/msg/Range").deserialize(cdr).variance == 0.0
    box = get_message_class("shape_msgs/SolidPrimitive")()
    box.dimensions = [1.0, 2.0, 3.0, 4.0]  # ROS 2 allows at most 3
    with pytest.raises(SerializationError, match="dimensions has 4 elements.*at most 3"):
        MAPPER.message("shape_msgs/SolidPrimitive").transcoder.ros1_to_cdr(ros1_bytes(box))


def test_bad_bytes_are_one_clear_error():
    t = MAPPER.message("sensor_msgs/CameraInfo").transcoder
    info = get_message_class("sensor_msgs/CameraInfo")()
    info.header.frame_id, info.D, info.distortion_model = "cam", [0.1, 0.2], "plumb_bob"
    raw = ros1_bytes(info)
    for end in range(len(raw)):
        with pytest.raises(DeserializationError):
            t.ros1_to_cdr(raw[:end])
    with pytest.raises(DeserializationError, match="3 bytes left over"):
        t.ros1_to_cdr(raw + b"abc")
    cdr = t.ros1_to_cdr(raw)
    for end in range(len(cdr)):
        with pytest.raises(DeserializationError):
            t.cdr_to_ros1(cdr[:end])
    with pytest.raises(DeserializationError, match="not little-endian plain CDR"):
        t.cdr_to_ros1(b"\x00\x00\x00\x00" + cdr[4:])
    lying = bytearray(raw)
    offset = raw.index(b"plumb_bob") + 9  # D's count
    lying[offset:offset + 4] = struct.pack("<I", 2 ** 31)
    with pytest.raises(DeserializationError, match="D needs 17179869184 bytes"):
        t.ros1_to_cdr(bytes(lying))


def test_a_1080p_image_costs_one_copy():
    image = get_message_class("sensor_msgs/Image")()
    image.height, image.width, image.encoding, image.step = 1080, 1920, "rgb8", 5760
    image.data = bytes(1920 * 1080 * 3)
    raw = ros1_bytes(image)
    t = MAPPER.message("sensor_msgs/Image").transcoder
    tracemalloc.start()
    try:
        cdr = t.ros1_to_cdr(raw)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.reset_peak()
        back = t.cdr_to_ros1(cdr, seq=image.header.seq)
        _, peak_back = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert back == raw
    assert peak < 1.05 * len(raw) and peak_back < 1.05 * len(raw) + len(cdr)
    source = t.source
    assert "out.append(v[p:p + _n" in source  # the pixels: a slice of the input, joined once


@pytest.mark.fuzz
def test_every_ros2_type_reaches_ros1_and_comes_back():
    """From ROS 2: every bundled message type, through its ROS 1 counterpart or the ROS 1 type
    made for it, and back; members ROS 1 lacks come back as their defaults."""
    from minros.ros2.types.testing import samples
    from minros.ros2.types.testing import strategy_for as ros2_strategy

    mapper = Mapper("jazzy")
    reg = mapper.ros2
    names = [n for n in reg.type_names("msg")]
    for name in names:
        m = mapper.message_from_ros2(name)
        codec = reg.codec(name)
        ros1_cls = mapper.ros1_context.get_class(m.ros1_type)
        for value in samples(ros2_strategy(reg, name), 3):
            ros1 = m.transcoder.cdr_to_ros1(codec.serialize(value))
            ros1_cls().deserialize(ros1)  # a valid ROS 1 message of that type
            expected = plain(reg, name, value)
            for path in m.all_defaulted():
                reset_plain(reg, name, expected, path)
            assert plain(reg, name, codec.deserialize(m.transcoder.ros1_to_cdr(ros1))) == \
                expected, name


def reset_plain(reg, name: str, value: dict, path: str) -> None:
    """Set the member at ``path`` (``markers[].texture``) of a plain value to its default."""
    head, _, rest = path.partition(".")
    member = reg.message(name).field(head.rstrip("[]"))
    if head.endswith("[]"):
        for item in value[member.name]:
            reset_plain(reg, member.type.base, item, rest)
    elif rest:
        reset_plain(reg, member.type.base, value[member.name], rest)
    else:
        value[member.name] = plain(reg, name, reg.codec(name).cls())[member.name]
