"""Tool internals that need no graph, against Debian's modules: rosmsg's texts, searches and
rosmsg-proto prototypes, catkin's workspace lookups (what roslib, roslaunch and rosmsg ask at
run time). One script, run by both interpreters, prints one JSON line."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

pytestmark = pytest.mark.interop

SCRIPT = r'''
import contextlib, io, json, os, sys
import rosmsg, rospkg, roslib.packages
from catkin.find_in_workspaces import find_in_workspaces
from catkin.workspace import CATKIN_MARKER_FILE, get_source_paths, get_workspaces
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import JointState
from std_msgs.msg import Int32

out = {}
rospack = rospkg.RosPack()
out["prototypes"] = [rosmsg.rosmsg_cmd_prototype(args) for args in (
    ["msg", "geometry_msgs/PoseStamped"], ["msg", "sensor_msgs/JointState", "-f", "1"],
    ["msg", "JointState", "-f", "0", "-p", "  "], ["srv", "std_srvs/SetBool", "-H"],
    ["msg", "std_msgs/Int32"], ["msg", "geometry_msgs/PoseStamped", "-x", "header"],
    ["msg", "visualization_msgs/Marker", "-e", "-f", "0"])]
out["yaml"] = [rosmsg.get_yaml_for_msg(JointState(), fill_arrays_=True),
               rosmsg.get_yaml_for_msg(JointState(name=["a", "b"], position=[1.0, 2, 3, 4, 5])),
               rosmsg.get_yaml_for_msg({"b": 1, "a": [1, 2]}, prefix="> "),
               rosmsg.get_yaml_for_msg(Int32(5), flow_style_=True),
               rosmsg.get_yaml_for_msg(PoseStamped(),
                                       field_filter=rosmsg.create_names_filter(["header"]))]
out["instances"] = [repr(rosmsg.get_array_type_instance(t, p)) for t, p in (
    ("Header", None), ("Point", "geometry_msgs"), ("float64[]", None), ("string", None),
    ("bool", None), ("Nope", None), ("empty", None))]
out["texts"] = [rosmsg.get_msg_text(t, raw=r) for t in ("std_msgs/Header", "geometry_msgs/PoseStamped",
                "std_msgs/Empty") for r in (False, True)]
out["srv_texts"] = [rosmsg.get_srv_text("std_srvs/SetBool", raw=r) for r in (False, True)]
for bad in (lambda: rosmsg.get_msg_text("nope_msgs/Nope"), lambda: rosmsg.get_srv_text("nope/Nope")):
    try:
        bad()
    except rosmsg.ROSMsgException as exc:
        out.setdefault("errors", []).append(str(exc).split(":")[0])
out["list_types"] = [rosmsg.list_types("std_srvs", rosmsg.MODE_SRV), rosmsg.list_msgs("std_msgs")[:5]]
out["search"] = sorted(rosmsg.rosmsg_search(rospack, rosmsg.MODE_MSG, "Header"))
out["iterate"] = "std_msgs" in [p for p, _ in rosmsg.iterate_packages(rospack, rosmsg.MODE_MSG)]
out["md5"] = [rosmsg.rosmsg_md5(rosmsg.MODE_SRV, "std_srvs/SetBool"),
              rosmsg.rosmsg_md5(rosmsg.MODE_MSG, "geometry_msgs/PoseStamped")]
try:
    rosmsg.rosmsg_md5(rosmsg.MODE_MSG, "nope_msgs/Nope")
except IOError as exc:
    out["md5_error"] = str(exc)
out["usage"] = [rosmsg.fullusage(rosmsg.MODE_MSG), rosmsg.fullusage(rosmsg.MODE_SRV)]
buff = io.StringIO()
with contextlib.redirect_stdout(buff):
    rosmsg.rosmsg_debug(rospack, rosmsg.MODE_SRV, "std_srvs/Trigger")
out["debug"] = buff.getvalue()
import genmsg
context = genmsg.MsgContext.create_default()
spec = genmsg.msg_loader.load_msg_from_string(context, "int32 A=1\nstd_msgs/Header h\nfloat64[] x\n", "p/T")
genmsg.msg_loader.load_depends(context, spec, {"std_msgs": [os.path.join(roslib.packages.get_pkg_dir("std_msgs"), "msg")]})
out["spec_to_str"] = rosmsg.spec_to_str(context, spec)
# catkin: a workspace with a source space, then the project's share folders in it
ws = sys.argv[1]
considered = []
out["workspaces"] = [w for w in get_workspaces() if w.startswith(ws)]
out["source_paths"] = get_source_paths(os.path.join(ws, "devel"))
found = find_in_workspaces(["share"], project="probe_pkg", path="launch",
                           considered_paths=considered)
out["find_share"] = [os.path.relpath(p, ws) for p in found if p.startswith(ws)]
out["find_first"] = [os.path.relpath(p, ws) for p in find_in_workspaces(
    ["share"], project="probe_pkg", first_match_only=True) if p.startswith(ws)]
out["considered"] = [os.path.relpath(p, ws) for p in considered if p.startswith(ws)]
out["find_lib"] = [os.path.relpath(p, ws) for p in find_in_workspaces(
    ["libexec"], project="probe_pkg", path="node.py") if p.startswith(ws)]
out["std_msgs_share"] = [os.path.basename(p) for p in find_in_workspaces(
    ["share"], project="std_msgs", first_match_only=True)]
for bad in (["nope"], ["bin"]):
    try:
        find_in_workspaces(bad, project="probe_pkg")
    except ValueError as exc:
        out.setdefault("search_errors", []).append(str(exc))
try:
    get_source_paths(ws)
except ValueError as exc:
    out["not_workspace"] = str(exc).replace(ws, "WS")
out["marker"] = CATKIN_MARKER_FILE
print(json.dumps(out, sort_keys=True))
'''


def _workspace(root: Path) -> Path:
    """A devel space with its .catkin marker and a source space holding probe_pkg."""
    src = root / "src"
    (src / "probe_pkg" / "launch").mkdir(parents=True)
    (src / "probe_pkg" / "package.xml").write_text(
        '<package format="2"><name>probe_pkg</name><version>0.1.0</version>'
        '<description>p</description><maintainer email="dev@example.com">a</maintainer>'
        '<license>BSD</license></package>')
    devel = root / "devel"
    (devel / "share" / "probe_pkg" / "launch").mkdir(parents=True)
    (devel / "lib" / "probe_pkg").mkdir(parents=True)
    (devel / "lib" / "probe_pkg" / "node.py").write_text("")
    (devel / ".catkin").write_text(f"{src};{src}")
    return root


def _run(python: str, root: Path, env: dict) -> dict:
    run = subprocess.run([python, "-c", SCRIPT, str(root)], env=env, capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout.strip().splitlines()[-1])


def test_rosmsg_and_catkin_answer_as_debians(tmp_path: Path) -> None:
    root = _workspace(tmp_path / "ws")
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    env["CMAKE_PREFIX_PATH"] = f"{root / 'devel'}:{tmp_path / 'not_a_workspace'}"
    env["ROS_HOME"] = str(tmp_path / "ros_home")
    ours = _run(PYTHON, root, env)
    assert ours["prototypes"][4] == '"data: 0"'
    assert ours["find_share"] == ["devel/share/probe_pkg/launch", "src/probe_pkg/launch"]
    assert ours["find_first"] == ["devel/share/probe_pkg"]
    assert ours["std_msgs_share"] == ["std_msgs"]
    require_reference()
    theirs = _run(REFERENCE_PYTHON, root, reference_env(env))
    assert ours == theirs
