"""The URDF joint reader: what robot_state_publisher and joint_state_publisher take from a
description, and one clear error for each kind of broken description."""

from __future__ import annotations

import math

import pytest

from minros.robot_state_publisher.kinematics import joint_transform
from minros.urdf_model import URDFError, parse_joints

ROBOT = """<robot name="r">
  <link name="a"/><link name="b"/><link name="c"/>
  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="1 0 0" rpy="0 0 1.5707963267948966"/><axis xyz="0 0 2"/>
    <limit lower="-1" upper="1"/><mimic joint="x" multiplier="2"/></joint>
  <joint name="j2" type="prismatic"><parent link="b"/><child link="c"/><axis xyz="1 0 0"/>
    <origin rpy="0 0 1.5707963267948966"/></joint>
</robot>"""


def test_joints_and_transforms() -> None:
    j1, j2 = parse_joints(ROBOT)
    assert (j1.name, j1.parent, j1.child, j1.axis, j1.lower) == ("j1", "a", "b", (0.0, 0.0, 1.0), -1.0)
    assert j1.mimic is not None and (j1.mimic.multiplier, j1.mimic.offset) == (2.0, 0.0)
    translation, rotation = joint_transform(j1, math.pi / 2)
    assert translation == (1.0, 0.0, 0.0)
    assert [round(v, 6) for v in rotation] == [0.0, 0.0, 1.0, 0.0]  # yaw pi/2 + pi/2
    translation, _ = joint_transform(j2, 0.5)  # along x of a frame turned by 90 degrees
    assert [round(v, 6) for v in translation] == [0.0, 0.5, 0.0]


@pytest.mark.parametrize("text, message", [
    ("<robot><joint", "not XML"),
    ("<model/>", "root element is <model>"),
    ('<robot><joint name="j" type="hinge"/></robot>', "has type 'hinge'"),
    ('<robot><joint name="j" type="fixed"><parent link="a"/></joint></robot>', "needs <parent"),
    ('<robot><joint name="j" type="fixed"><parent link="a"/><child link="b"/>'
     '<origin xyz="1 2"/></joint></robot>', "origin xyz: '1 2' is not three numbers"),
    ('<robot><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
     '<axis xyz="0 0 0"/></joint></robot>', "zero axis"),
    ('<robot><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
     '<limit lower="low"/></joint></robot>', "lower='low' is not a number"),
])
def test_broken_descriptions(text: str, message: str) -> None:
    with pytest.raises(URDFError, match=message):
        parse_joints(text)


def test_joint_state_publisher_takes_the_first_robot_of_a_urdf_root() -> None:
    """A description whose root is <urdf> holding a <robot>: joint_state_publisher reads the
    first <robot> of the document (Debian's: ``robot.getElementsByTagName('robot')[0]``), so
    its joints are the robot's; robot_state_publisher's rule (urdfdom's: the root is the
    <robot>) still refuses it."""
    from minros.joint_state_publisher.joints import JointTable

    robot = ROBOT.replace('<mimic joint="x" multiplier="2"/>', "")
    wrapped = f'<urdf version="1">\n<!-- a comment -->\n{robot}\n</urdf>'
    bare, inside = JointTable(robot), JointTable(wrapped)
    assert inside.order == bare.order == ["j1", "j2"]
    assert inside.free == bare.free and list(inside.free) == ["j1"]
    assert [j.name for j in parse_joints(wrapped, robot_anywhere=True)] == ["j1", "j2"]
    with pytest.raises(URDFError, match="root element is <urdf>, not <robot>"):
        parse_joints(wrapped)
    with pytest.raises(URDFError, match="root element is <urdf>, not <robot>"):
        JointTable("<urdf><link name='a'/></urdf>")
