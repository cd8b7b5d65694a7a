"""ROS 1 <-> ROS 2 type mapping by ros1_bridge's rules (minros.ros2.types.mapping)."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from minros.msgs import get_message_class
from minros.ros2.types import (
    ACTION_STATUS_1_TO_2,
    ACTION_STATUS_2_TO_1,
    Mapper,
    NoMappingError,
    registry,
)
from minros.ros2.types.mapping import ros2_msg_text


@pytest.fixture(scope="module")
def mapper():
    return Mapper("jazzy")


def ros1_bytes(msg) -> bytes:
    buf = io.BytesIO()
    msg.serialize(buf)
    return buf.getvalue()


def test_same_package_and_name_fields_by_lower_case(mapper):
    m = mapper.message("sensor_msgs/CameraInfo")
    assert m.ros2_type == "sensor_msgs/msg/CameraInfo" and not m.generated
    sources = {link.ros2.name: link.ros1_path for link in m.links}
    assert [sources[n] for n in "dkrp"] == [("D",), ("K",), ("R",), ("P",)]
    assert m.all_dropped() == ["header.seq"] and m.all_defaulted() == []
    assert m.type_hash == registry("jazzy").type_hash("sensor_msgs/msg/CameraInfo")
    assert m.dds_type_name == "sensor_msgs::msg::dds_::CameraInfo_"


def test_packages_pair_as_ros1_bridge_pairs_them_and_by_rule(mapper):
    assert mapper.ros2_type_for("std_msgs/Header") == "std_msgs/msg/Header"
    assert mapper.message("std_msgs/Header").dropped == ["seq"]
    # explicit in ros1_bridge
    assert mapper.ros2_type_for("std_msgs/Time") == "builtin_interfaces/msg/Time"
    assert mapper.ros2_type_for("std_msgs/Duration") == "builtin_interfaces/msg/Duration"
    # the rules ROS 2's packages ship (tf2_msgs, unique_identifier_msgs, rcl_interfaces)
    assert mapper.ros2_type_for("tf/tfMessage") == "tf2_msgs/msg/TFMessage"
    assert mapper.ros2_type_for("uuid_msgs/UniqueID") == "unique_identifier_msgs/msg/UUID"
    log = mapper.message("rosgraph_msgs/Log")
    assert log.ros2_type == "rcl_interfaces/msg/Log"
    assert log.all_dropped() == ["header.seq", "header.frame_id", "topics"]
    assert [link.ros1_path for link in log.links][:2] == [("header", "stamp"), ("level",)]
    # same package name (not a _msgs package: ros1_bridge would not pair these)
    assert mapper.ros2_type_for("turtlesim/Pose") == "turtlesim/msg/Pose"
    # members ROS 1 lacks take their defaults
    assert mapper.message("sensor_msgs/Range").defaulted == ["variance"]
    assert mapper.message("visualization_msgs/Marker").defaulted == [
        "texture_resource", "texture", "uv_coordinates", "mesh_file"]


def test_reverse_lookup(mapper):
    assert mapper.ros1_type_for("std_msgs/msg/String") == "std_msgs/String"
    assert mapper.ros1_type_for("builtin_interfaces/msg/Time") == "std_msgs/Time"
    assert mapper.ros1_type_for("rcl_interfaces/msg/Log") == "rosgraph_msgs/Log"
    assert mapper.ros1_type_for("sensor_msgs/msg/Image") == "sensor_msgs/Image"
    with pytest.raises(NoMappingError, match="no ROS 1 type maps to it"):
        mapper.ros1_type_for("rcl_interfaces/msg/ParameterEvent")


def test_unmatched_fields_on_both_sides_is_no_mapping_with_the_reason():
    mapper = Mapper("jazzy")
    mapper.add_ros1_definition("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 height\n")
    with pytest.raises(NoMappingError) as info:
        mapper.message("geometry_msgs/Point")
    assert "ROS 1 field(s) height and geometry_msgs/msg/Point field(s) z have no partner" \
        in str(info.value)
    # and what embeds it cannot map either, saying which field
    with pytest.raises(NoMappingError, match=r"field position \(geometry_msgs/Point\)"):
        mapper.message("geometry_msgs/Pose")
    mapper.add_ros1_definition("std_msgs/String", "int32 data\n")
    with pytest.raises(NoMappingError, match="different primitive types"):
        mapper.message("std_msgs/String")
    mapper.add_ros1_definition("std_msgs/Float64MultiArray",
                               "std_msgs/MultiArrayLayout layout\nfloat64[4] data\n")
    with pytest.raises(NoMappingError, match="a fixed-length array and a variable one"):
        mapper.message("std_msgs/Float64MultiArray")


#: a bag's own ROS 1 definitions: a message_definition text, as a bag or connection carries it
BAG_DEFINITION = (Path(__file__).parent / "ros2_fixtures" / "my_robot_msgs_Status.txt").read_text()


def test_a_ros1_type_without_counterpart_gets_a_ros2_type_from_its_definition():
    mapper = Mapper("jazzy")
    assert mapper.add_ros1_definition("my_robot_msgs/Status", BAG_DEFINITION)[0] == \
        "my_robot_msgs/Status"
    m = mapper.message("my_robot_msgs/Status")
    assert m.generated and m.ros2_type == "my_robot_msgs/msg/Status"
    struct = m.ros2
    assert [(f.name, f.type.msg_text()) for f in struct.fields] == [
        ("header", "std_msgs/Header"), ("start", "builtin_interfaces/Time"),
        ("took", "builtin_interfaces/Duration"), ("raw", "byte"), ("letter", "char"),
        ("position", "float64[3]"), ("wheels", "my_robot_msgs/Wheel[]"),
        ("pose", "geometry_msgs/Pose")]
    assert [(c.name, c.value) for c in struct.constants] == [
        ("COUNT_MAX", 10), ("LABEL", "hello # ROS 1 keeps this comment in the value")]
    assert struct.text == ("int32 COUNT_MAX=10\nstd_msgs/Header header\n"
                           "builtin_interfaces/Time start\nbuiltin_interfaces/Duration took\n"
                           "byte raw\nchar letter\nfloat64[3] position\n"
                           "my_robot_msgs/Wheel[] wheels\ngeometry_msgs/Pose pose\n")
    assert mapper.ros2.message("my_robot_msgs/msg/Wheel").fields[0].name == "name"
    assert m.all_dropped() == ["header.seq"]
    assert m.type_hash.startswith("RIHS01_") and len(m.type_hash) == 71
    # the shared registry stays as it was
    assert not registry("jazzy").has("my_robot_msgs/msg/Status")
    # the pose inside is ROS 2's own geometry_msgs/Pose
    assert struct.field("pose").type.base == "geometry_msgs/msg/Pose"


def test_names_equal_but_for_case_cannot_map():
    mapper = Mapper("jazzy")
    mapper.add_ros1_definition("odd_msgs/Twice", "int32 x\nint32 X\n")
    with pytest.raises(NoMappingError, match="fields 'x' and 'X' are one name in ROS 2"):
        mapper.message("odd_msgs/Twice")
    strict = Mapper("jazzy", generate=False)
    with pytest.raises(NoMappingError, match="making one from the ROS 1 definition is off"):
        strict.message("rosgraph_msgs/TopicStatistics")


def test_services_map_request_and_response():
    mapper = Mapper("jazzy")
    s = mapper.service("std_srvs/SetBool")
    assert (s.ros2_type, s.generated) == ("std_srvs/srv/SetBool", False)
    assert s.request.ros2_type == "std_srvs/srv/SetBool_Request"
    assert s.response.transcoder.ros1_to_cdr(ros1_bytes(
        get_message_class("std_srvs/SetBoolResponse")(True, "ok"))).hex() == \
        "00010000" "01000000" "03000000" "6f6b00"
    assert mapper.service("turtlesim/Spawn").ros2_type == "turtlesim/srv/Spawn"
    assert mapper.service("std_srvs/Empty").request.ros2.is_empty
    made = mapper.service("roscpp/GetLoggers")  # ROS 1 only
    assert made.generated and made.ros2_type == "roscpp/srv/GetLoggers"
    assert mapper.ros2.type_hash("roscpp/srv/GetLoggers").startswith("RIHS01_")
    assert mapper.ros2.message("roscpp/srv/GetLoggers_Event").fields[0].name == "info"


def test_actions_map_their_parts_and_say_what_does_not():
    mapper = Mapper("jazzy")
    a = mapper.action("tf2_msgs/LookupTransform")
    assert (a.ros2_type, a.generated) == ("tf2_msgs/action/LookupTransform", False)
    assert a.goal.ros2_type == "tf2_msgs/action/LookupTransform_Goal"
    assert [link.ros2.type.base for link in a.goal.links][2:4] == [
        "builtin_interfaces/msg/Time", "builtin_interfaces/msg/Duration"]
    assert any("GoalID" in note for note in a.notes)
    made = mapper.action("actionlib_tutorials/Fibonacci")
    assert made.generated and made.result.ros2_type == "actionlib_tutorials/action/Fibonacci_Result"
    assert mapper.ros2.type_hash("actionlib_tutorials/action/Fibonacci").startswith("RIHS01_")
    # the ROS 1 envelopes bridge as plain messages, GoalID included
    assert mapper.message("actionlib_msgs/GoalStatusArray").ros2_type == \
        "actionlib_msgs/msg/GoalStatusArray"
    assert ACTION_STATUS_1_TO_2[3] == 4 and ACTION_STATUS_2_TO_1[4] == 3  # SUCCEEDED
    assert 5 not in ACTION_STATUS_1_TO_2  # REJECTED: accepted=false in SendGoal's response


def test_ros2_msg_text_is_what_rosidl_reads_back():
    from minros.ros2.types import parse_msg

    m = Mapper("jazzy")
    m.add_ros1_definition("my_robot_msgs/Status", BAG_DEFINITION)
    struct = m.message("my_robot_msgs/Status").ros2
    again = parse_msg(struct.text, struct.name)
    assert [(f.name, f.type) for f in again.fields] == [(f.name, f.type) for f in struct.fields]
    assert ros2_msg_text(struct.fields, []).startswith("std_msgs/Header header\n")


def test_ros2_types_without_ros1_counterpart_get_a_ros1_type():
    mapper = Mapper("jazzy")
    m = mapper.message_from_ros2("rcl_interfaces/msg/ParameterEvent")
    assert m.ros1_type == "rcl_interfaces/ParameterEvent"
    assert m.ros1.text.startswith("time stamp\nstring node\nrcl_interfaces/Parameter[] ")
    assert len(mapper.ros1_context.md5sum("rcl_interfaces/ParameterEvent")) == 32
    assert "MSG: rcl_interfaces/ParameterValue" in \
        mapper.ros1_context.full_text("rcl_interfaces/ParameterEvent")
    # a counterpart is used where there is one
    assert mapper.message_from_ros2("sensor_msgs/msg/Image").ros1_type == "sensor_msgs/Image"
    # Header becomes ROS 1's, with its seq
    made = mapper.message_from_ros2("action_msgs/msg/GoalStatusArray")
    assert made.ros1_type == "action_msgs/GoalStatusArray"
    reg = mapper.ros2.child()
    reg.add_definition("msg", "w_msgs/msg/Wide", "wstring text\n")
    wide = Mapper("jazzy", ros2=reg)
    with pytest.raises(NoMappingError, match="wstring, which ROS 1 has no type for"):
        wide.message_from_ros2("w_msgs/msg/Wide")
