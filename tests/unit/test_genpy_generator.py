"""genpy.generator (minros.msgs.pygen): the modules it writes import and work under minros,
their bytes are minros's own classes' bytes, and its command line writes a package; genmsg's
line parsers. Debian's genpy as the oracle of the text: tests/interop/test_genpy_generator_oracle.py."""

from __future__ import annotations

import io
import subprocess
import sys
from pathlib import Path

import pytest

import genmsg.command_line
import genpy.generate_struct
import genpy.generator
from genmsg import InvalidMsgSpec
from genmsg.msg_loader import (
    MsgContext,
    _load_constant_line,
    _load_field_line,
    convert_constant_value,
    load_msg_by_type,
    load_srv_by_type,
)
from minros.packages import find_package


def search_path(*packages: str) -> dict:
    return {p: [str(find_package(p) / "msg")] for p in packages}


def module_of(lines) -> dict:
    namespace: dict = {}
    exec(compile("\n".join(lines), "<generated>", "exec"), namespace)
    return namespace


def test_reduce_pattern_counts_runs_but_not_digits():
    assert genpy.generate_struct.reduce_pattern("hhhhiiiibbb") == "4h4i3b"
    # an array length of 99 stays a length (genpy 0.6.16 turned '99d' into '29d')
    assert genpy.generate_struct.reduce_pattern("99d") == "99d"
    assert genpy.generate_struct.reduce_pattern("%ss") == "%ss"


def test_generated_pose_stamped_matches_minros_bytes_both_ways():
    import genpy
    from geometry_msgs.msg import Point, Pose, PoseStamped, Quaternion
    from std_msgs.msg import Header

    context = MsgContext.create_default()
    paths = search_path("std_msgs", "geometry_msgs")
    spec = load_msg_by_type(context, "geometry_msgs/PoseStamped", paths)
    genpy.generator.reset_var()
    cls = module_of(genpy.generator.msg_generator(context, spec, paths))["PoseStamped"]
    assert cls._md5sum == PoseStamped._md5sum and cls._full_text == PoseStamped._full_text
    ours = PoseStamped(Header(7, genpy.Time(3, 4), "map"),
                       Pose(Point(1.5, -2, 3), Quaternion(0, 0, 0.5, 1)))
    want = io.BytesIO()
    ours.serialize(want)
    got = io.BytesIO()
    cls(header=ours.header, pose=ours.pose).serialize(got)
    assert got.getvalue() == want.getvalue()
    back = cls().deserialize(want.getvalue())
    assert (back.header.frame_id, back.header.stamp, back.pose.orientation.z) == ("map", genpy.Time(3, 4), 0.5)


def test_generated_service_module_names_its_classes_and_md5():
    from std_srvs.srv import SetBool

    context = MsgContext.create_default()
    srv_dir = str(find_package("std_srvs") / "srv")
    spec = load_srv_by_type(context, "std_srvs/SetBool", {"std_srvs": [srv_dir]})
    module = module_of(genpy.generator.srv_generator(context, spec, {}))
    assert module["SetBool"]._md5sum == SetBool._md5sum
    assert module["SetBool"]._request_class is module["SetBoolRequest"]
    buff = io.BytesIO()
    module["SetBoolResponse"](success=True, message="ok").serialize(buff)
    assert SetBool._response_class().deserialize(buff.getvalue()).message == "ok"


@pytest.mark.slow
def test_genmsg_py_command_line_writes_a_package(tmp_path: Path):
    msg_dir = tmp_path / "msg"
    msg_dir.mkdir()
    (msg_dir / "Pair.msg").write_text("int32 A=1\nstring name\nfloat64[2] xy\n")
    out = tmp_path / "out"
    code = ("import sys; from genpy.generator import MsgGenerator; from genpy.genpy_main import genmain; "
            "genmain(sys.argv, 'genmsg_py.py', MsgGenerator())")
    run = [sys.executable, "-c", code, "-p", "demo", "-o", str(out), f"-Idemo:{msg_dir}"]
    subprocess.run([*run, str(msg_dir / "Pair.msg")], check=True, timeout=60)
    subprocess.run([*run[:3], "--initpy", "-o", str(out)], check=True, timeout=60)
    assert (out / "__init__.py").read_text() == "from ._Pair import *\n"
    namespace = module_of((out / "_Pair.py").read_text().splitlines())
    pair = namespace["Pair"](name="p", xy=[1.0, 2.0])
    assert pair.A == 1 and pair.xy == [1.0, 2.0]


def test_generate_messages_reports_a_bad_file_and_goes_on(tmp_path: Path, capsys):
    (tmp_path / "Bad.msg").write_text("int32 x\nnot a field line\n")
    (tmp_path / "Good.msg").write_text("int32 x\n")
    rc = genpy.generator.MsgGenerator().generate_messages(
        "demo", [str(tmp_path / "Bad.msg"), str(tmp_path / "Good.msg")], str(tmp_path / "o"),
        {"demo": [str(tmp_path)]})
    assert rc == 1
    assert "Unable to generate messages for package 'demo'" in capsys.readouterr().err
    assert (tmp_path / "o" / "_Good.py").exists()


def test_genmsg_line_parsers():
    assert convert_constant_value("uint8", "255") == 255
    with pytest.raises(InvalidMsgSpec):
        convert_constant_value("uint8", "256")  # out of range: the spec is invalid
    with pytest.raises(ValueError):
        convert_constant_value("int32", "f")  # not a number
    assert _load_constant_line("string s=a # b").val == "a # b"
    assert _load_field_line("Header h", "") == ("std_msgs/Header", "h")
    assert _load_field_line("Point p # c", "geometry_msgs") == ("geometry_msgs/Point", "p")
    with pytest.raises(InvalidMsgSpec):
        _load_field_line("string[ data", "pkg")
    assert genmsg.command_line.includepath_to_dict(["a:/x", "a:/y", "b:"]) == {"a": ["/x", "/y"]}
