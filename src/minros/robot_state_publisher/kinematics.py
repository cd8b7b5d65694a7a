"""A joint's transform (parent link -> child link) at a position, without I/O."""

from __future__ import annotations

import math
from typing import Tuple

from minros.urdf_model import Joint, rpy_to_quaternion

Vec3 = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]


def quat_multiply(a: Quat, b: Quat) -> Quat:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def rotate(q: Quat, v: Vec3) -> Vec3:
    x, y, z, w = q
    vx, vy, vz = v
    # v + 2w (q x v) + 2 q x (q x v)
    cx, cy, cz = y * vz - z * vy, z * vx - x * vz, x * vy - y * vx
    cx2, cy2, cz2 = y * cz - z * cy, z * cx - x * cz, x * cy - y * cx
    return (vx + 2 * (w * cx + cx2), vy + 2 * (w * cy + cy2), vz + 2 * (w * cz + cz2))


def joint_transform(joint: Joint, position: float = 0.0) -> Tuple[Vec3, Quat]:
    """(translation, rotation) of ``joint``'s child link in its parent link: the origin, then
    the motion (a rotation about the axis, or a translation along it)."""
    origin_q = rpy_to_quaternion(*joint.rpy)
    if joint.type in ("revolute", "continuous"):
        half = position / 2.0
        s = math.sin(half)
        motion = (joint.axis[0] * s, joint.axis[1] * s, joint.axis[2] * s, math.cos(half))
        return joint.xyz, quat_multiply(origin_q, motion)
    if joint.type == "prismatic":
        shift = rotate(origin_q, tuple(a * position for a in joint.axis))  # type: ignore[arg-type]
        return (joint.xyz[0] + shift[0], joint.xyz[1] + shift[1], joint.xyz[2] + shift[2]), origin_q
    return joint.xyz, origin_q
