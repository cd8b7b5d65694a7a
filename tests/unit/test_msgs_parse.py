"""Parsing .msg/.srv text, md5 text, full text and malformed-definition errors."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from minros.msgs import MsgContext, MsgSpecError, generate_dynamic, get_message_class
from minros.msgs.spec import (
    SEPARATOR,
    compute_md5_text,
    parse_msg,
    parse_srv,
    split_full_text,
)


def _context(**texts: str) -> MsgContext:
    """A context holding the given definitions (keys: 'pkg__Type')."""
    ctx = MsgContext(search=False)
    for key, text in texts.items():
        ctx.add_spec(parse_msg(text, key.replace("__", "/")))
    return ctx


def test_fields_comments_constants_and_resolution() -> None:
    spec = parse_msg(
        "# leading comment\n"
        "Header header   # trailing comment\n"
        "int32 X=5 # constant comment\n"
        "string NAME= hello # not a comment  \n"
        "bool FLAG=True\n"
        "char C=255\n"
        "byte B=-128\n"
        "float64 PI=3.14\n"
        "\n"
        "Point p\n"
        "geometry_msgs/Point[] ps\n"
        "uint8[16] id\n"
        "time t\n"
        "duration[] ds\n",
        "pkg/Thing")
    assert [(f.type, f.name) for f in spec.fields] == [
        ("std_msgs/Header", "header"), ("pkg/Point", "p"), ("geometry_msgs/Point[]", "ps"),
        ("uint8[16]", "id"), ("time", "t"), ("duration[]", "ds")]
    consts = {c.name: (c.type, c.value, c.val_text) for c in spec.constants}
    assert consts["X"] == ("int32", 5, "5")
    assert consts["NAME"] == ("string", "hello # not a comment", "hello # not a comment")
    assert consts["FLAG"] == ("bool", True, "True")
    assert consts["C"] == ("char", 255, "255")
    assert consts["B"] == ("byte", -128, "-128")
    assert consts["PI"] == ("float64", 3.14, "3.14")
    assert spec.has_header
    fixed = spec.fields[3]
    assert (fixed.base_type, fixed.is_array, fixed.array_len) == ("uint8", True, 16)


def test_constants_become_class_attributes() -> None:
    log = get_message_class("rosgraph_msgs/Log")
    assert (log.DEBUG, log.INFO, log.WARN, log.ERROR, log.FATAL) == (1, 2, 4, 8, 16)
    ctx = _context(pkg__C="string S=a=b # c\nbool T=False\nint8 N=-3\nint32 x")
    cls = ctx.get_class("pkg/C")
    assert (cls.S, cls.T, cls.N) == ("a=b # c", False, -3)
    assert "S" not in cls.__slots__ and cls.__slots__ == ["x"]


def test_md5_text_puts_constants_first_and_replaces_embedded_types() -> None:
    ctx = _context(pkg__Inner="int32 a", pkg__Outer="Inner[] xs\nint32 K=7 # c\nfloat64[3] v\nInner one")
    inner_md5 = ctx.md5sum("pkg/Inner")
    assert ctx.md5_text("pkg/Outer") == (
        f"int32 K=7\n{inner_md5} xs\nfloat64[3] v\n{inner_md5} one")
    spec = parse_msg("  \n# only comments\n", "pkg/Empty")
    assert compute_md5_text(spec, ctx.md5sum) == ""
    assert _context(pkg__E="").md5sum("pkg/E") == "d41d8cd98f00b204e9800998ecf8427e"


def test_md5_ignores_comments_whitespace_and_package_names() -> None:
    a = _context(p1__Inner="int32 a", p1__T="# c\nInner   x  # c\n\nstring s")
    b = _context(p2__Inner="int32 a # other", p2__T="p2/Inner x\nstring   s")
    assert a.md5sum("p1/T") == b.md5sum("p2/T")
    c = _context(p3__T="int32 x\nstring s")
    assert c.md5sum("p3/T") != a.md5sum("p1/T")


def test_full_text_depth_first_unique_and_no_final_newline() -> None:
    ctx = _context(
        pkg__A="B b\nC c\nB again",
        pkg__B="C c # comment",
        pkg__C="int8 x\n",
    )
    full = ctx.full_text("pkg/A")
    assert full == (
        "B b\nC c\nB again\n"
        + SEPARATOR + "\nMSG: pkg/B\nC c # comment\n"
        + SEPARATOR + "\nMSG: pkg/C\nint8 x\n")


def test_split_full_text_and_generate_dynamic_round_trip() -> None:
    ros_log = get_message_class("rosgraph_msgs/Log")
    blocks = split_full_text(ros_log._full_text)
    assert [t for t, _ in blocks] == [None, "std_msgs/Header"]
    classes = generate_dynamic("rosgraph_msgs/Log", ros_log._full_text)
    dyn = classes["rosgraph_msgs/Log"]
    assert set(classes) == {"rosgraph_msgs/Log", "std_msgs/Header"}
    assert dyn is not ros_log
    assert dyn._md5sum == ros_log._md5sum and dyn._full_text == ros_log._full_text
    msg = ros_log(level=2, name="/n", msg="hi", topics=["/a"])
    msg.header.stamp.secs = 7
    data = msg.serialize_to_bytes()
    back = dyn().deserialize(data)
    assert (back.level, back.name, back.topics, back.header.stamp.secs) == (2, "/n", ["/a"], 7)
    assert back.serialize_to_bytes() == data
    assert dyn.WARN == 4
    # cached: the same text gives the same classes
    assert generate_dynamic("rosgraph_msgs/Log", ros_log._full_text)["rosgraph_msgs/Log"] is dyn


def test_generate_dynamic_needs_msg_lines() -> None:
    with pytest.raises(MsgSpecError, match="MSG:"):
        generate_dynamic("a/B", "int8 x\n" + SEPARATOR + "\nint8 y")
    with pytest.raises(LookupError, match="c/D"):
        generate_dynamic("a/B", "c/D d")
    # embedded types missing from the text come from the installed definitions
    classes = generate_dynamic("a/C", "Header h\ngeometry_msgs/Point p")
    assert classes["a/C"]._md5sum == generate_dynamic(
        "a/C", "Header h\ngeometry_msgs/Point p\n" + SEPARATOR + "\nMSG: std_msgs/Header\n"
        + get_message_class("std_msgs/Header")._full_text)["a/C"]._md5sum


def test_srv_split_like_genmsg() -> None:
    spec = parse_srv("int64 a # x\nint64 b\n---ignored text\nint64 sum\n", "pkg/Add")
    assert spec.request.text == "int64 a # x\nint64 b\n"
    assert spec.response.text == "int64 sum\n\n"
    assert [f.name for f in spec.response.fields] == ["sum"]
    assert spec.request.full_name == "pkg/AddRequest"


@pytest.mark.parametrize("text, line, needle", [
    ("int32 x\nint32 x y\n", 2, "invalid declaration"),
    ("int32 x\n\nfoo-bar y\n", 3, "not a legal message field type"),
    ("int32 1x\n", 1, "not a legal message field name"),
    ("int32 x\nint32 x\n", 2, "duplicate field name"),
    ("time T=3\n", 1, "not a legal constant type"),
    ("uint8 X=256\n", 1, "out of bounds"),
    ("int8 X=-129\n", 1, "out of bounds"),
    ("int32 X=abc\n", 1, "invalid constant value"),
    ("bool B=maybe\n", 1, "invalid constant value"),
    ("int32[x] a\n", 1, "not a legal message field type"),
    ("int32[2][3] a\n", 1, "not a legal message field type"),
    ("int32 A=1=2\n", 1, "invalid constant declaration"),
    ("int32\n", 1, "invalid declaration"),
])
def test_malformed_msg_names_file_and_line(text: str, line: int, needle: str) -> None:
    with pytest.raises(MsgSpecError) as info:
        parse_msg(text, "pkg/Bad", "/ws/src/pkg/msg/Bad.msg")
    err = info.value
    assert err.filename == "/ws/src/pkg/msg/Bad.msg" and err.lineno == line
    assert str(err).startswith(f"/ws/src/pkg/msg/Bad.msg:{line}: ")
    assert needle in str(err)
    assert isinstance(err, ValueError)


def test_malformed_srv_response_line_numbers() -> None:
    with pytest.raises(MsgSpecError) as info:
        parse_srv("int32 a\n---\nint32 ok\nbad line here\n", "pkg/S", "S.srv")
    assert info.value.lineno == 4


def test_recursive_definition_is_an_error() -> None:
    ctx = _context(pkg__A="B b", pkg__B="A a")
    with pytest.raises(MsgSpecError, match="recursive"):
        ctx.md5sum("pkg/A")


def test_malformed_file_in_package_names_path(tmp_path, monkeypatch) -> None:
    pkg = tmp_path / "badpkg"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>badpkg</name></package>")
    (pkg / "msg" / "Broken.msg").write_text("int32 ok\nstring\n")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    with pytest.raises(MsgSpecError) as info:
        get_message_class("badpkg/Broken")
    assert str(info.value).startswith(f"{pkg / 'msg' / 'Broken.msg'}:2: ")


_TOKENS = ["int32", "uint8", "string", "bool", "time", "Header", "pkg/T", "x", "y", "X", "[]",
           "[3]", "[", "]", "=", "1", "-1", "True", "#", " ", "  ", "\n", "---", "abc", "1.5", "/"]


@settings(max_examples=300, deadline=None, database=None)
@given(st.lists(st.sampled_from(_TOKENS), max_size=30))
def test_random_definitions_parse_or_raise_msgspecerror(tokens: list) -> None:
    text = "".join(tokens)
    try:
        spec = parse_msg(text, "pkg/Fuzz", "Fuzz.msg")
        parse_srv(text, "pkg/FuzzSrv", "Fuzz.srv")
    except MsgSpecError as exc:
        assert exc.filename and exc.lineno
        return
    for f in spec.fields:
        assert f.name and f.type
