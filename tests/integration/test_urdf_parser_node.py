"""urdf_parser_py's ``URDF.from_parameter_server()`` in a rospy node under ``minros core``: the
description set on the master (as roslaunch's <param> sets it) is read through the node's
parameter API, relative keys resolve in the node's namespace, and a missing key is rospy's
KeyError. ``rosrun urdfdom_py display_urdf`` prints the parameter's robot."""

from __future__ import annotations

import subprocess
import xmlrpc.client
from pathlib import Path

import pytest

from support import PYTHON, Proc, ros_env

ROBOT = """<robot name="arm">
  <link name="base"/><link name="upper"/><link name="tool"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 0 1"/><limit lower="-1.5" upper="1.5" effort="10" velocity="2"/></joint>
  <joint name="wrist" type="fixed"><parent link="upper"/><child link="tool"/></joint>
</robot>"""

NODE = r'''
import rospy
from urdf_parser_py.urdf import URDF

rospy.init_node("urdf_reader")
robot = URDF.from_parameter_server()
print("default", robot.name, robot.get_chain(robot.get_root(), "tool"), flush=True)
limit = URDF.from_parameter_server("/left/robot_description").joint_map["shoulder"].limit
print("key", limit.lower, limit.upper, flush=True)
try:
    URDF.from_parameter_server("no_description")
except KeyError as exc:
    print("missing", exc.args, flush=True)
'''


@pytest.mark.smoke
def test_from_parameter_server_in_a_node(tmp_path: Path, minros_core: int, ros_home: Path) -> None:
    env = ros_env(minros_core, ros_home)
    master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
    # the node runs in /ns: its "robot_description" is /ns/robot_description, not the global one
    assert master.setParam("/test", "/ns/robot_description", ROBOT)[0] == 1
    assert master.setParam("/test", "/robot_description", ROBOT.replace('"arm"', '"other"'))[0] == 1
    assert master.setParam("/test", "/left/robot_description", ROBOT)[0] == 1
    script = tmp_path / "urdf_reader.py"
    script.write_text(NODE)
    proc = Proc([PYTHON, str(script), "__ns:=/ns"], env)
    try:
        out = proc.read_until("missing", 60)
    finally:
        proc.stop()
    lines = [line for line in out.splitlines() if not line.startswith("[")]
    assert lines == ["default arm ['base', 'shoulder', 'upper', 'wrist', 'tool']",
                     "key -1.5 1.5",
                     "missing ('no_description',)"], out  # rospy's KeyError(key), as given


def test_display_urdf_reads_robot_description(minros_core: int, ros_home: Path) -> None:
    from minros.workspace import executables

    env = ros_env(minros_core, ros_home)
    argv = executables.resolve_executable("urdfdom_py", "display_urdf")
    missing = subprocess.run(argv, capture_output=True, text=True, env=env, timeout=60)
    assert (missing.returncode, missing.stdout) == (1, "")
    assert missing.stderr.startswith("display_urdf: the parameter robot_description is not set")
    master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
    assert master.setParam("/test", "/robot_description", ROBOT)[0] == 1
    shown = subprocess.run(argv + ["-o", "-"], capture_output=True, text=True, env=env, timeout=60)
    assert shown.returncode == 0 and shown.stderr == "", shown.stderr
    assert "\nname: arm\n" in shown.stdout
    assert '<limit effort="10.0" lower="-1.5" upper="1.5" velocity="2.0"/>' in shown.stdout
