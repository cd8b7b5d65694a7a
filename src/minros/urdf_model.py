"""The joints of a URDF robot, as robot_state_publisher and joint_state_publisher read them
(pure: text in, joints out; no lxml).

Only what those two programs use is read: each joint's name, type, parent and child links,
origin, axis, limits, safety controller and mimic tag. Floating and planar joints are kept
with their type: robot_state_publisher publishes them as fixed (as ROS's, through KDL, does)
and joint_state_publisher skips them.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

__all__ = ["URDFError", "Joint", "Mimic", "parse_joints", "rpy_to_quaternion"]

Vec3 = Tuple[float, float, float]
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


class URDFError(ValueError):
    """A robot description that cannot be read; the message names the element."""


@dataclass
class Mimic:
    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass
class Joint:
    name: str
    type: str
    parent: str
    child: str
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)
    axis: Vec3 = (1.0, 0.0, 0.0)
    lower: Optional[float] = None
    upper: Optional[float] = None
    soft_lower: Optional[float] = None
    soft_upper: Optional[float] = None
    mimic: Optional[Mimic] = None
    extra: Dict[str, str] = field(default_factory=dict)

    @property
    def moving(self) -> bool:
        return self.type in ("revolute", "continuous", "prismatic")


def _vec(text: Optional[str], default: Vec3, where: str) -> Vec3:
    if text is None:
        return default
    parts = text.split()
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise URDFError(f"{where}: '{text}' is not three numbers") from None
    if len(values) != 3:
        raise URDFError(f"{where}: '{text}' is not three numbers")
    return values  # type: ignore[return-value]


def _float(element: ET.Element, attr: str, where: str) -> Optional[float]:
    text = element.get(attr)
    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        raise URDFError(f"{where}: {attr}='{text}' is not a number") from None


def parse_joints(description: str, robot_anywhere: bool = False) -> List[Joint]:
    """The joints of a URDF ``<robot>``, in document order. The root must be the ``<robot>``
    (urdfdom's rule, robot_state_publisher's), or with ``robot_anywhere`` the first ``<robot>``
    in the document is taken, as joint_state_publisher's ``getElementsByTagName('robot')[0]``
    does (a ``<urdf>`` root holding a ``<robot>``)."""
    try:
        root = ET.fromstring(description)
    except ET.ParseError as exc:
        raise URDFError(f"the robot description is not XML: {exc}") from None
    if root.tag != "robot" and robot_anywhere:
        root = next(root.iter("robot"), root)
    if root.tag != "robot":
        raise URDFError(f"the robot description's root element is <{root.tag}>, not <robot>")
    joints = []
    for element in root.findall("joint"):
        name = element.get("name", "")
        where = f"joint '{name}'"
        jtype = element.get("type", "")
        if not name:
            raise URDFError("a <joint> has no name")
        if jtype not in JOINT_TYPES:
            raise URDFError(f"{where} has type '{jtype}' (one of {', '.join(JOINT_TYPES)})")
        parent, child = element.find("parent"), element.find("child")
        if parent is None or child is None or not parent.get("link") or not child.get("link"):
            raise URDFError(f"{where} needs <parent link=...> and <child link=...>")
        joint = Joint(name, jtype, parent.get("link", ""), child.get("link", ""))
        origin = element.find("origin")
        if origin is not None:
            joint.xyz = _vec(origin.get("xyz"), (0.0, 0.0, 0.0), f"{where} origin xyz")
            joint.rpy = _vec(origin.get("rpy"), (0.0, 0.0, 0.0), f"{where} origin rpy")
        axis = element.find("axis")
        if axis is not None:
            joint.axis = _vec(axis.get("xyz"), (1.0, 0.0, 0.0), f"{where} axis")
            norm = math.sqrt(sum(a * a for a in joint.axis))
            if norm == 0.0:
                raise URDFError(f"{where} has a zero axis")
            joint.axis = tuple(a / norm for a in joint.axis)  # type: ignore[assignment]
        limit = element.find("limit")
        if limit is not None:
            joint.lower = _float(limit, "lower", f"{where} limit")
            joint.upper = _float(limit, "upper", f"{where} limit")
        safety = element.find("safety_controller")
        if safety is not None:
            joint.soft_lower = _float(safety, "soft_lower_limit", f"{where} safety_controller")
            joint.soft_upper = _float(safety, "soft_upper_limit", f"{where} safety_controller")
        mimic = element.find("mimic")
        if mimic is not None:
            if not mimic.get("joint"):
                raise URDFError(f"{where}: <mimic> needs joint=...")
            multiplier = _float(mimic, "multiplier", f"{where} mimic")
            offset = _float(mimic, "offset", f"{where} mimic")
            joint.mimic = Mimic(mimic.get("joint", ""), 1.0 if multiplier is None else multiplier,
                                0.0 if offset is None else offset)
        joints.append(joint)
    return joints


def rpy_to_quaternion(roll: float, pitch: float, yaw: float) -> Tuple[float, float, float, float]:
    """(x, y, z, w) of the fixed-axis rotation roll about X, then pitch about Y, then yaw
    about Z (URDF's convention)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)
