"""ROS 2 .msg/.srv/.action parsing with rosidl's rules (minros.ros2.types.parse)."""

from __future__ import annotations

from pathlib import Path

import pytest

from minros.msgs.spec import MsgSpecError
from minros.ros2.types import TypeRegistry, parse_action, parse_msg, parse_srv
from minros.ros2.types.model import ARRAY, BOUNDED, EMPTY_MEMBER, SCALAR, SEQUENCE, FieldType

FIXTURES = Path(__file__).parent / "ros2_fixtures"


def test_types_arrays_and_bounds():
    m = parse_msg("string<=10 name\nfloat64[9] k\nint32[<=3] few\nPoint[] points\n"
                  "geometry_msgs/Pose pose\nwstring<=4[2] wide\n", "pkg/msg/T")
    by_name = {f.name: f.type for f in m.fields}
    assert by_name["name"] == FieldType("string", SCALAR, 0, 10)
    assert by_name["k"] == FieldType("float64", ARRAY, 9)
    assert by_name["few"] == FieldType("int32", BOUNDED, 3)
    assert by_name["points"] == FieldType("pkg/msg/Point", SEQUENCE)  # ROS 2: same package
    assert by_name["pose"] == FieldType("geometry_msgs/msg/Pose")
    assert by_name["wide"] == FieldType("wstring", ARRAY, 2, 4)
    assert by_name["wide"].msg_text() == "wstring<=4[2]"
    assert m.name == "pkg/msg/T" and m.package == "pkg" and m.short_name == "T"


def test_ros1_time_and_header_spellings():
    m = parse_msg("time stamp\nduration[] waits\nHeader header\n", "pkg/Thing")
    assert [f.type.base for f in m.fields] == [
        "builtin_interfaces/msg/Time", "builtin_interfaces/msg/Duration",
        "pkg/msg/Header"]  # no implicit std_msgs/Header in ROS 2


def test_comments_tabs_defaults_and_constants():
    text = ("# file comment\n"
            "int32\tcount  5   # a default\n"
            "string greeting \"hi there\"\n"
            "string quoted 'it\\'s'\n"
            "bool[3] flags [true, 0, FALSE]\n"
            "string[] names [\"a, b\", 'c']\n"
            "int32 X=0x10\n"
            "string S = text # not part of the value in ROS 2\n"
            "uint8 MAX = 255\n")
    m = parse_msg(text, "pkg/msg/D")
    values = {f.name: f.default for f in m.fields}
    assert values == {"count": 5, "greeting": "hi there", "quoted": "it's",
                      "flags": [True, False, False], "names": ["a, b", "c"]}
    assert {c.name: c.value for c in m.constants} == {"X": 16, "S": "text", "MAX": 255}
    assert m.field_lines == {"count": 2, "greeting": 3, "quoted": 4, "flags": 5, "names": 6}
    assert m.fields[3].default_text == "(True, False, False)"


def test_empty_message_gets_rosidls_placeholder():
    m = parse_msg("# nothing\n\nint8 CONSTANT=1\n", "pkg/msg/Empty")
    assert [f.name for f in m.fields] == [EMPTY_MEMBER]
    assert m.fields[0].type == FieldType("uint8") and m.is_empty


@pytest.mark.parametrize("text, line, words", [
    ("int32 a\nfloat64[0] b\n", 2, "integer > 0"),
    ("int32 a\nuint8 b 256\n", 2, "out of range"),
    ("int8 a -129\n", 1, "out of range"),
    ("bool a maybe\n", 1, "true/false"),
    ("int32 a\nint32 a\n", 2, "duplicate field name 'a' (first declared on line 1)"),
    ("string<=x s\n", 1, "upper bound"),
    ("int32[3] a [1, 2]\n", 1, "exactly 3 elements"),
    ("int32[<=1] a [1, 2]\n", 1, "at most 1 elements"),
    ("pkg/Other[] a [1]\n", 1, "only primitive types"),
    ("int32\n", 1, "expected 'TYPE NAME'"),
    ("a/b/c/D x\n", 1, "is not a type"),
    ("int32[] C=1\n", 1, "only primitive types"),
    ("string<=3 s \"long\"\n", 1, "longer than its bound"),
    ("string s \"un\"closed\"\n", 1, "inner quotes must be escaped"),
])
def test_errors_name_file_and_line(text, line, words):
    with pytest.raises(MsgSpecError) as info:
        parse_msg(text, "pkg/msg/Bad", "/some/pkg/msg/Bad.msg")
    assert str(info.value).startswith(f"/some/pkg/msg/Bad.msg:{line}: ")
    assert words in str(info.value)


def test_service_and_its_parts():
    srv = parse_srv("# request\nint64 a\nint64 b\n---\nint64 sum\n", "pkg/srv/Add")
    assert srv.request.name == "pkg/srv/Add_Request"
    assert srv.response.name == "pkg/srv/Add_Response"
    assert srv.event is not None and srv.event.name == "pkg/srv/Add_Event"
    assert [(f.name, f.type.msg_text()) for f in srv.event.fields] == [
        ("info", "service_msgs/ServiceEventInfo"), ("request", "pkg/Add_Request[<=1]"),
        ("response", "pkg/Add_Response[<=1]")]
    assert srv.response.field_lines == {"sum": 5}
    assert parse_srv("---\n", "pkg/Nothing", with_event=False).event is None
    with pytest.raises(MsgSpecError, match=r"x\.srv: a service needs exactly 1 line"):
        parse_srv("int32 a\n", "pkg/srv/Bad", "x.srv")
    with pytest.raises(MsgSpecError, match="found 2"):
        parse_srv("---\n---\n", "pkg/srv/Bad")
    with pytest.raises(MsgSpecError, match=r"x\.srv:4: "):
        parse_srv("int32 a\n---\nint32 b\nfloat x y z\n", "pkg/srv/Bad", "x.srv")


def test_action_and_its_derived_types():
    action = parse_action("int32 order\n---\nint32[] sequence\n---\nint32[] partial\n",
                          "pkg/action/Fib")
    assert action.goal.name == "pkg/action/Fib_Goal"
    assert [f.name for f in action.send_goal.request.fields] == ["goal_id", "goal"]
    assert [(f.name, f.type.base) for f in action.send_goal.response.fields] == [
        ("accepted", "bool"), ("stamp", "builtin_interfaces/msg/Time")]
    assert [(f.name, f.type.base) for f in action.get_result.response.fields] == [
        ("status", "int8"), ("result", "pkg/action/Fib_Result")]
    assert action.feedback_message.name == "pkg/action/Fib_FeedbackMessage"
    assert action.send_goal.event is not None
    with pytest.raises(MsgSpecError, match="exactly 2 line"):
        parse_action("int32 a\n---\n", "pkg/action/Bad")


def test_registry_resolves_every_part_name():
    reg = TypeRegistry("jazzy")
    assert reg.message("tf2_msgs/action/LookupTransform_SendGoal_Request").fields[1].type.base \
        == "tf2_msgs/action/LookupTransform_Goal"
    assert [f.name for f in reg.message("std_srvs/srv/SetBool").fields] == [
        "request_message", "response_message", "event_message"]
    assert len(reg.message("turtlesim/action/RotateAbsolute").fields) == 6
    assert reg.message("std_msgs/String") is reg.message("std_msgs/msg/String")
    assert "geometry_msgs/msg/Twist" in reg.type_names("msg")
    assert "turtlesim/action/RotateAbsolute" in reg.type_names("action")


def test_unknown_types_say_where_minros_looked():
    from minros.msgs.registry import UnknownTypeError

    reg = TypeRegistry("kilted")
    with pytest.raises(UnknownTypeError, match=r"package \[no_such_pkg\] not found"):
        reg.message("no_such_pkg/msg/X")
    with pytest.raises(UnknownTypeError, match=r"no msg/Nope\.msg in package \[std_msgs\].*kilted"):
        reg.message("std_msgs/msg/Nope")
    with pytest.raises(UnknownTypeError, match="no _Event type"):
        TypeRegistry("humble").message("std_srvs/srv/SetBool_Event")


def test_child_registry_keeps_its_types_and_shared_ones_are_read_only():
    from minros.ros2.types import registry

    shared = registry("jazzy")
    with pytest.raises(RuntimeError, match="read-only"):
        shared.add_definition("msg", "mine/msg/Foo", "int32 x\n")
    child = shared.child()
    child.add_definition("msg", "mine/msg/Foo", "std_msgs/Header header\nint32 x\n")
    assert child.message("mine/msg/Foo").fields[0].type.base == "std_msgs/msg/Header"
    assert child.type_hash("mine/msg/Foo").startswith("RIHS01_")
    assert not shared.has("mine/msg/Foo")
    # a search path of ROS 2 packages (share/<pkg>/msg/*.msg, as an install has)
    assert TypeRegistry("jazzy", paths=[FIXTURES]).message(
        "test_interface_files/msg/Defaults").field("int8_value").default == -50


def test_the_test_interface_files_parse():
    reg = TypeRegistry("jazzy", paths=[FIXTURES])
    defaults = reg.message("test_interface_files/msg/Defaults")
    assert {f.name: f.default for f in defaults.fields}["float32_value"] == 1.125
    strings = reg.message("test_interface_files/msg/Strings")
    assert strings.field("bounded_string_value_default4").default == "Hello'world!"
    assert strings.field("bounded_string_value").type.string_bound == 22
    for kind in ("msg", "srv", "action"):
        for name in reg.type_names(kind):
            if name.startswith("test_interface_files/"):
                getattr(reg, {"msg": "message", "srv": "service", "action": "action"}[kind])(name)
