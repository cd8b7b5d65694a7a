"""The simulated robot's model: a TurtleBot3 Burger-like URDF of boxes and cylinders.

Link names, joint origins and sizes follow turtlebot3_description's burger (noetic), so a
course's frame names (``base_footprint``, ``base_link``, ``base_scan``, ``wheel_left_link``,
...) exist; the meshes are replaced by their collision shapes, so no file needs serving. The
wheels are continuous joints: the simulator publishes their angles on ``joint_states`` and
their transforms itself, as the Gazebo plugin and robot_state_publisher would between them.
"""

from __future__ import annotations

from typing import List, NamedTuple, Tuple

from minros.sim.world import LASER_OFFSET


class FixedFrame(NamedTuple):
    """A fixed joint: ``parent -> child`` at ``xyz`` with rotation ``rpy``."""

    parent: str
    child: str
    xyz: Tuple[float, float, float]
    rpy: Tuple[float, float, float]


#: base_footprint -> base_link is 1 cm up; the LDS sits on top, 3.2 cm behind the centre
FIXED_FRAMES: List[FixedFrame] = [
    FixedFrame("base_footprint", "base_link", (0.0, 0.0, 0.010), (0.0, 0.0, 0.0)),
    FixedFrame("base_link", "base_scan", (LASER_OFFSET[0], LASER_OFFSET[1], 0.172), (0.0, 0.0, 0.0)),
    FixedFrame("base_link", "caster_back_link", (-0.081, 0.0, -0.004), (-1.57, 0.0, 0.0)),
    FixedFrame("base_link", "imu_link", (-0.032, 0.0, 0.068), (0.0, 0.0, 0.0)),
]
#: the wheels' joint origins (continuous joints about their z axis)
WHEELS = {
    "wheel_left_joint": FixedFrame("base_link", "wheel_left_link", (0.0, 0.08, 0.023), (-1.57, 0.0, 0.0)),
    "wheel_right_joint": FixedFrame("base_link", "wheel_right_link", (0.0, -0.08, 0.023), (-1.57, 0.0, 0.0)),
}


def _fmt(values: Tuple[float, ...]) -> str:
    return " ".join(f"{v:g}" for v in values)


def urdf(name: str = "turtlebot3_burger_minros") -> str:
    """The URDF text (what ``/robot_description`` holds)."""
    def visual(geometry: str, xyz: Tuple[float, float, float] = (0.0, 0.0, 0.0),
               rpy: Tuple[float, float, float] = (0.0, 0.0, 0.0), material: str = "dark") -> str:
        origin = f'<origin xyz="{_fmt(xyz)}" rpy="{_fmt(rpy)}"/>'
        return (f"    <visual>{origin}<geometry>{geometry}</geometry>"
                f'<material name="{material}"/></visual>\n'
                f"    <collision>{origin}<geometry>{geometry}</geometry></collision>\n")

    lines = [f'<?xml version="1.0"?>\n<robot name="{name}">\n',
             '  <material name="dark"><color rgba="0.3 0.3 0.3 1"/></material>\n',
             '  <material name="black"><color rgba="0.05 0.05 0.05 1"/></material>\n',
             '  <material name="light"><color rgba="0.8 0.8 0.8 1"/></material>\n',
             '  <link name="base_footprint"/>\n',
             '  <link name="base_link">\n'
             + visual('<box size="0.14 0.14 0.143"/>', (-0.032, 0.0, 0.070))
             + "  </link>\n",
             '  <link name="base_scan">\n'
             + visual('<cylinder length="0.0315" radius="0.055"/>', (0.015, 0.0, -0.0065), material="black")
             + "  </link>\n",
             '  <link name="caster_back_link">\n'
             + visual('<box size="0.030 0.009 0.020"/>', (0.0, 0.001, 0.0), material="light")
             + "  </link>\n",
             '  <link name="imu_link"/>\n']
    for side in ("left", "right"):
        lines.append(f'  <link name="wheel_{side}_link">\n'
                     + visual('<cylinder length="0.018" radius="0.033"/>', material="black")
                     + "  </link>\n")
    joints = {"base_joint": FIXED_FRAMES[0], "scan_joint": FIXED_FRAMES[1],
              "caster_back_joint": FIXED_FRAMES[2], "imu_joint": FIXED_FRAMES[3]}
    for joint, frame in joints.items():
        lines.append(f'  <joint name="{joint}" type="fixed"><parent link="{frame.parent}"/>'
                     f'<child link="{frame.child}"/>'
                     f'<origin xyz="{_fmt(frame.xyz)}" rpy="{_fmt(frame.rpy)}"/></joint>\n')
    for joint, frame in WHEELS.items():
        lines.append(f'  <joint name="{joint}" type="continuous"><parent link="{frame.parent}"/>'
                     f'<child link="{frame.child}"/>'
                     f'<origin xyz="{_fmt(frame.xyz)}" rpy="{_fmt(frame.rpy)}"/>'
                     '<axis xyz="0 0 1"/></joint>\n')
    lines.append("</robot>\n")
    return "".join(lines)
