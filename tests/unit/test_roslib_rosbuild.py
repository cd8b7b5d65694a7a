"""roslib's rosbuild-era API (roslib.msgs, srvs, gentools, manifest, resources, rospack,
scriptutil): the specs it parses, the md5 sums and full texts it computes (equal to the
message classes', which the interop suite checks against Debian), its errors."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import roslib.gentools
import roslib.manifest
import roslib.msgs
import roslib.resources
import roslib.rospack
import roslib.scriptutil
import roslib.srvs
from roslib.exceptions import ROSLibException


def test_roslib_msgs_is_one_module_with_its_state():
    import minros.msgs.rosbuild.msgs as impl

    assert roslib.msgs is impl
    roslib.msgs.reinit()
    assert roslib.msgs._initialized and roslib.msgs.is_registered("roslib/Header")


def test_load_from_string_keeps_header_and_qualifies_local_types():
    spec = roslib.msgs.load_from_string("Header header\nPoint p\nint8 X=3\nstring s", "geo")
    assert spec.types == ["Header", "geo/Point", "string"] and spec.has_header()
    assert [(c.name, c.val) for c in spec.constants] == [("X", 3)]
    with pytest.raises(roslib.msgs.MsgSpecException, match="out of bounds"):
        roslib.msgs.load_from_string("int8 X=300")
    with pytest.raises(roslib.msgs.MsgSpecException, match="not a legal message field name"):
        roslib.msgs.load_from_string("int8 9x")


@pytest.mark.parametrize("type_name", ["geometry_msgs/PoseStamped", "sensor_msgs/Imu",
                                       "rosgraph_msgs/Log", "visualization_msgs/MarkerArray"])
def test_md5_and_full_text_equal_the_message_classes(type_name):
    from minros.msgs import get_message_class

    cls = get_message_class(type_name)
    package, short = type_name.split("/")
    _, spec = roslib.msgs.load_from_file(roslib.msgs.msg_file(package, short), package)
    deps = roslib.gentools.get_dependencies(spec, package, compute_files=True)
    assert roslib.gentools.compute_md5(deps) == cls._md5sum
    assert roslib.gentools.compute_full_text(deps) == cls._full_text
    assert all(Path(f).is_file() for f in deps["files"].values())


def test_service_spec_and_md5():
    from std_srvs.srv import SetBool

    name, spec = roslib.srvs.load_from_file(roslib.srvs.srv_file("std_srvs", "SetBool"), "std_srvs/")
    assert name == "std_srvs/SetBool" and spec.response.names == ["success", "message"]
    deps = roslib.gentools.get_dependencies(spec, "std_srvs", compute_files=False)
    assert "files" not in deps and roslib.gentools.compute_md5(deps) == SetBool._md5sum


def test_missing_dependency_names_the_type():
    spec = roslib.msgs.load_from_string("nosuch_msgs/Thing t", "std_msgs")
    with pytest.raises(roslib.msgs.MsgSpecException, match="Cannot load type 'nosuch_msgs/Thing'"):
        roslib.gentools.get_dependencies(spec, "std_msgs")


def test_manifest_resources_and_rospack(tmp_path: Path, monkeypatch):
    pkg = tmp_path / "old_pkg"
    (pkg / "msg").mkdir(parents=True)
    (pkg / "msg" / "A.msg").write_text("int32 a\n")
    (pkg / "manifest.xml").write_text(
        "<package><description brief='b'>d</description><author>a</author>"
        "<license>BSD</license><depend package='std_msgs'/>"
        "<export><std_msgs plugin='${prefix}/p.xml'/></export></package>")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    manifest = roslib.manifest.load_manifest("old_pkg")
    assert [d.package for d in manifest.depends] == ["std_msgs"]
    assert roslib.resources.list_package_resources("old_pkg", False, "msg") == ["A.msg"]
    assert roslib.msgs.list_msg_types("old_pkg", False) == ["A"]
    assert roslib.rospack.rospack_depends_1("old_pkg") == ["std_msgs"]
    assert "old_pkg" in roslib.rospack.rospack_depends_on_1("std_msgs")
    assert roslib.rospack.rospack_plugins("std_msgs") == [("old_pkg", f"{pkg}/p.xml")]
    with pytest.raises(ROSLibException, match="package 'nope' not found"):
        roslib.rospack.rospack_depends("nope")
    with pytest.raises(Exception, match="no manifest file"):
        roslib.manifest.load_manifest("std_msgs")  # a catkin package has no manifest.xml


def test_scriptutil_resolves_without_remapping(monkeypatch):
    monkeypatch.setenv("ROS_NAMESPACE", "/ns")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        assert roslib.scriptutil.script_resolve_name("s", "~p") == "/ns/s/p"
        assert roslib.scriptutil.script_resolve_name("s", "t") == "/ns/t"
        assert roslib.scriptutil.script_resolve_name("s", "/g") == "/g"
    with pytest.warns(DeprecationWarning):
        roslib.scriptutil.script_resolve_name("s", "x")
