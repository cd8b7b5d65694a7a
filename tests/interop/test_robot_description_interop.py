"""A robot brought up as ROS users do, on minros's roslaunch with a Debian rosmaster:
``<param name="robot_description" command="$(find xacro)/xacro $(find myrobot)/...">`` (PyPI's
xacro with minros's package lookup), minros's robot_state_publisher and joint_state_publisher
— each beside Debian's own (C++ robot_state_publisher, Python joint_state_publisher) on
remapped topics, fed the same description and joint states: they publish the same joints,
positions and transforms."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, Proc, need, reference_env, ros_env

pytestmark = pytest.mark.interop

DEBIAN_RSP = "/usr/lib/robot_state_publisher/robot_state_publisher"
DEBIAN_JSP = "/usr/lib/joint_state_publisher/joint_state_publisher"

MACROS = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="link_box" params="name">
    <link name="${name}"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
  </xacro:macro>
</robot>
"""

ROBOT = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="arm_len" default="1.0"/>
  <xacro:property name="len" value="$(arg arm_len)"/>
  <xacro:include filename="$(find myrobot)/urdf/macros.xacro"/>
  <xacro:link_box name="base_link"/>
  <xacro:link_box name="shoulder"/>
  <xacro:link_box name="upper"/>
  <xacro:link_box name="fore"/>
  <xacro:link_box name="slider"/>
  <xacro:link_box name="finger"/>
  <xacro:link_box name="camera"/>
  <xacro:link_box name="wheel"/>
  <joint name="pan" type="revolute">
    <parent link="base_link"/><child link="shoulder"/>
    <origin xyz="0 0 0.2" rpy="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="1" velocity="1"/>
  </joint>
  <joint name="tilt" type="revolute">
    <parent link="shoulder"/><child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0.1 0.2 0"/><axis xyz="0 1 1"/>
    <limit lower="0.2" upper="1.2" effort="1" velocity="1"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/>
    <origin xyz="${len} 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
    <safety_controller soft_lower_limit="-1" soft_upper_limit="1" k_velocity="1"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="fore"/><child link="slider"/>
    <origin xyz="0.1 0 0" rpy="0 1.5707963 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.3" effort="1" velocity="1"/>
  </joint>
  <joint name="grip" type="prismatic">
    <parent link="slider"/><child link="finger"/>
    <axis xyz="0 1 0"/><limit lower="-0.1" upper="0.1" effort="1" velocity="1"/>
    <mimic joint="slide" multiplier="-0.5" offset="0.01"/>
  </joint>
  <joint name="spin" type="continuous">
    <parent link="base_link"/><child link="wheel"/><axis xyz="1 0 0"/>
  </joint>
  <joint name="cam_mount" type="fixed">
    <parent link="fore"/><child link="camera"/><origin xyz="0.05 0 0.02" rpy="0 0.5 0"/>
  </joint>
</robot>
"""

PACKAGE = """<?xml version="1.0"?>
<package format="2"><name>myrobot</name><version>0.0.1</version><description>t</description>
<maintainer email="a@b.c">a</maintainer><license>BSD</license>
<buildtool_depend>catkin</buildtool_depend></package>
"""

LAUNCH = """<launch>
  <param name="robot_description"
         command="$(find xacro)/xacro $(find myrobot)/urdf/robot.xacro arm_len:=0.5"/>
  <rosparam param="zeros">{elbow: 0.3, slide: 0.2}</rosparam>
  <node pkg="robot_state_publisher" type="robot_state_publisher" name="rsp"/>
  <node pkg="joint_state_publisher" type="joint_state_publisher" name="jsp"/>
</launch>
"""

PROBE = r'''
import json, time
import rospy
from tf2_msgs.msg import TFMessage
from sensor_msgs.msg import JointState
rospy.init_node("probe")
got = {"tf": {}, "tf_deb": {}, "static": None, "static_deb": None, "js": None, "js_deb": None}

def key(t):
    return t.header.frame_id + ">" + t.child_frame_id

def plain(t):
    v, q = t.transform.translation, t.transform.rotation
    return [round(x, 5) for x in (v.x, v.y, v.z, q.x, q.y, q.z, q.w)]

def on_tf(msg, name):
    for t in msg.transforms:
        got[name].setdefault(str(t.header.stamp.to_nsec()), {})[key(t)] = plain(t)

def on_static(msg, name):
    got[name] = {key(t): plain(t) for t in msg.transforms}

def on_js(msg, name):
    got[name] = [list(msg.name), [round(p, 6) for p in msg.position]]

rospy.Subscriber("/tf", TFMessage, on_tf, "tf")
rospy.Subscriber("/tf_deb", TFMessage, on_tf, "tf_deb")
rospy.Subscriber("/tf_static", TFMessage, on_static, "static")
rospy.Subscriber("/tf_static_deb", TFMessage, on_static, "static_deb")
rospy.Subscriber("/joint_states", JointState, on_js, "js")
rospy.Subscriber("/joint_states_deb", JointState, on_js, "js_deb")
deadline = time.time() + 40
while time.time() < deadline:
    common = set(got["tf"]) & set(got["tf_deb"])
    if len(common) >= 3 and all(got[k] for k in ("static", "static_deb", "js", "js_deb")):
        break
    time.sleep(0.2)
common = sorted(set(got["tf"]) & set(got["tf_deb"]))
print("GOT " + json.dumps({"pairs": [[got["tf"][s], got["tf_deb"][s]] for s in common[:5]],
      "static": got["static"], "static_deb": got["static_deb"], "js": got["js"],
      "js_deb": got["js_deb"],
      "description": rospy.get_param("/robot_description")}), flush=True)
'''


def test_xacro_robot_state_and_joint_state_publishers(tmp_path: Path, debian_rosmaster: int,
                                                      ros_home: Path) -> None:
    need(os.access(DEBIAN_RSP, os.X_OK) and Path(DEBIAN_JSP).exists(),
         "Debian's robot_state_publisher/joint_state_publisher are not installed",
         "scripts/install-ros-reference.sh")
    pkg = tmp_path / "ws" / "myrobot"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "package.xml").write_text(PACKAGE)
    (pkg / "urdf" / "macros.xacro").write_text(MACROS)
    (pkg / "urdf" / "robot.xacro").write_text(ROBOT)
    launch = tmp_path / "bringup.launch"
    launch.write_text(LAUNCH)
    probe_script = tmp_path / "probe.py"
    probe_script.write_text(PROBE)
    env = ros_env(debian_rosmaster, ros_home, {"ROS_PACKAGE_PATH": str(tmp_path / "ws")})
    denv = reference_env(ros_env(debian_rosmaster, ros_home))
    roslaunch = Proc([str(Path(PYTHON).parent / "roslaunch"), str(launch)], env)
    procs = [roslaunch]
    try:
        roslaunch.read_until("started with pid", 60)
        # Debian's programs on remapped topics, same parameters
        done = subprocess.run(["/usr/bin/rosparam", "set", "/jsp_deb/zeros", "{elbow: 0.3, slide: 0.2}"],
                              env=denv, capture_output=True, text=True, timeout=30)
        assert done.returncode == 0, done.stderr
        procs.append(Proc([DEBIAN_RSP, "__name:=rsp_deb", "/tf:=/tf_deb",
                           "/tf_static:=/tf_static_deb"], denv))
        procs.append(Proc([REFERENCE_PYTHON, DEBIAN_JSP, "__name:=jsp_deb",
                           "joint_states:=joint_states_deb"], denv))
        probe = Proc([REFERENCE_PYTHON, str(probe_script)], denv)
        procs.append(probe)
        out = probe.read_until("GOT ", 60)
        got = json.loads(out.split("GOT ", 1)[1].splitlines()[0])
        # xacro expanded the include, the macro, the argument and $(find myrobot)
        assert '<joint name="elbow" type="revolute">' in got["description"]
        assert 'xyz="0.5 0 0"' in got["description"]
        # joint_state_publisher: names in URDF order, zeros, limit midpoints, mimic
        assert got["js"] == got["js_deb"], got
        assert got["js"][0] == ["pan", "tilt", "elbow", "slide", "grip", "spin"]
        assert got["js"][1] == [0.0, 0.7, 0.3, 0.2, -0.09, 0.0]
        # robot_state_publisher: the same fixed and moving transforms for the same stamps
        assert got["static"] == got["static_deb"], got
        assert set(got["static"]) == {"fore>camera"}
        assert got["pairs"], got
        for ours, theirs in got["pairs"]:
            assert ours == theirs
        assert set(got["pairs"][0][0]) == {"base_link>shoulder", "shoulder>upper", "upper>fore",
                                           "fore>slider", "slider>finger", "base_link>wheel"}
    finally:
        for proc in reversed(procs):
            proc.stop()


def test_xacro_command_line_and_missing_package(tmp_path: Path) -> None:
    pkg = tmp_path / "ws" / "myrobot"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "package.xml").write_text(PACKAGE)
    (pkg / "urdf" / "macros.xacro").write_text(MACROS)
    (pkg / "urdf" / "robot.xacro").write_text(ROBOT)
    env = {**os.environ, "ROS_PACKAGE_PATH": str(tmp_path / "ws")}
    rosrun = str(Path(PYTHON).parent / "rosrun")
    done = subprocess.run([rosrun, "xacro", "xacro", str(pkg / "urdf" / "robot.xacro")],
                          env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert '<origin xyz="1.0 0 0"/>' in done.stdout
    bad = tmp_path / "bad.xacro"
    bad.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
                   '<xacro:include filename="$(find no_such_pkg)/x.xacro"/></robot>')
    failed = subprocess.run([rosrun, "xacro", "xacro", str(bad)], env=env, capture_output=True,
                            text=True, timeout=60)
    assert failed.returncode != 0
    assert "no_such_pkg" in failed.stderr and "Traceback" not in failed.stderr, failed.stderr


URDF = """<robot name="r">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <joint name="pan" type="revolute"><parent link="base"/><child link="a"/>
    <limit lower="-1.5" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="lift" type="prismatic"><parent link="a"/><child link="b"/>
    <limit lower="0.2" upper="0.4" effort="1" velocity="1"/>
    <safety_controller soft_lower_limit="0.25" soft_upper_limit="0.5" k_velocity="1"/></joint>
  <joint name="grip" type="prismatic"><parent link="b"/><child link="c"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/>
    <mimic joint="lift" multiplier="-0.5" offset="0.01"/></joint>
  <joint name="spin" type="continuous"><parent link="base"/><child link="d"/></joint>
</robot>"""

JSP_API = r'''
import json, rospy, joint_state_publisher as jsp
from sensor_msgs.msg import JointState
rospy.init_node("jsp_api", anonymous=True)
publisher = jsp.JointStatePublisher()
calls = []
publisher.set_source_update_cb(lambda: calls.append(1))
publisher.source_cb(JointState(name=["pan", "nope", "spin"], position=[0.5, 9.0, 2.0]))
print(json.dumps({"free": publisher.free_joints, "list": publisher.joint_list,
                  "dependent": publisher.dependent_joints, "calls": len(calls),
                  "rate": jsp.get_param("rate", 10), "zeros": jsp.get_param("zeros"),
                  "topic": publisher.pub.resolved_name}, sort_keys=True))
'''


def test_joint_state_publisher_module_as_debians(debian_rosmaster: int, ros_home: Path) -> None:
    """joint_state_publisher's JointStatePublisher (what joint_state_publisher_gui builds on)
    reads the description and parameters into the same joint tables as Debian's, and takes a
    source's values the same way."""
    denv = reference_env(ros_env(debian_rosmaster, ros_home))
    for args in (["/robot_description", URDF], ["/zeros", "{pan: 0.3}"], ["/use_sim_time", "false"]):
        done = subprocess.run(["/usr/bin/rosparam", "set", *args], env=denv, capture_output=True,
                              text=True, timeout=30)
        assert done.returncode == 0, done.stderr
    env = ros_env(debian_rosmaster, ros_home)
    ours = subprocess.run([PYTHON, "-c", JSP_API], env=env, capture_output=True, text=True,
                          timeout=60)
    assert ours.returncode == 0, ours.stderr
    mine = json.loads(ours.stdout.strip().splitlines()[-1])
    assert mine["list"] == ["pan", "lift", "grip", "spin"] and mine["calls"] == 1
    assert mine["free"]["pan"]["position"] == 0.5 and mine["free"]["spin"]["continuous"] is True
    theirs = subprocess.run([REFERENCE_PYTHON, "-c", JSP_API], env=denv, capture_output=True,
                            text=True, timeout=60)
    assert theirs.returncode == 0, theirs.stderr
    assert mine == json.loads(theirs.stdout.strip().splitlines()[-1])
