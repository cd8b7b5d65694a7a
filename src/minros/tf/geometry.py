"""tf2_geometry_msgs: apply a geometry_msgs/TransformStamped to geometry_msgs stamped types.

Importing this module registers the conversions with tf2_ros, so that
``buffer.transform(point_stamped, "map")`` works, as ``import tf2_geometry_msgs`` does in
ROS. The arithmetic is what ROS's version does through PyKDL: rotation by q v q* (so a
slightly denormalised quaternion scales the result by |q|^2 as there), and a pose's
orientation with KDL's sign choice (w > 0 unless the rotation is near a half turn).
The result's header is the transform's header, as in ROS.
"""

from __future__ import annotations

from typing import Any, Tuple

from geometry_msgs.msg import (
    PointStamped,
    PoseStamped,
    Vector3Stamped,
    WrenchStamped,
)

from .buffer import ConvertRegistration, TransformRegistration
from .core import _rotate


def _parts(transform: Any) -> Tuple[Tuple[float, float, float], Tuple[float, float, float, float]]:
    t = transform.transform
    v, r = t.translation, t.rotation
    return (v.x, v.y, v.z), (r.x, r.y, r.z, r.w)


def _kdl_sign(q: Tuple[float, float, float, float]) -> Tuple[float, float, float, float]:
    """The sign KDL's Rotation::GetQuaternion gives a rotation's quaternion."""
    x, y, z, w = q
    xx, yy, zz, ww = x * x, y * y, z * z, w * w
    trace = 3.0 * ww - xx - yy - zz  # of the rotation matrix
    if trace > 1e-12:
        keep = w >= 0
    else:
        r00, r11, r22 = ww + xx - yy - zz, ww - xx + yy - zz, ww - xx - yy + zz
        if r00 > r11 and r00 > r22:
            keep = x >= 0
        elif r11 > r22:
            keep = y >= 0
        else:
            keep = z >= 0
    return q if keep else (-x, -y, -z, -w)


def to_msg_msg(msg: Any) -> Any:
    return msg


def from_msg_msg(msg: Any) -> Any:
    return msg


def do_transform_point(point: Any, transform: Any) -> Any:
    """A geometry_msgs/PointStamped in the transform's target frame."""
    (tx, ty, tz), q = _parts(transform)
    p = point.point
    x, y, z = _rotate(q[0], q[1], q[2], q[3], p.x, p.y, p.z)
    res = PointStamped()
    res.point.x, res.point.y, res.point.z = x + tx, y + ty, z + tz
    res.header = transform.header
    return res


def do_transform_vector3(vector3: Any, transform: Any) -> Any:
    """A geometry_msgs/Vector3Stamped rotated into the target frame (no translation)."""
    _, q = _parts(transform)
    v = vector3.vector
    res = Vector3Stamped()
    res.vector.x, res.vector.y, res.vector.z = _rotate(q[0], q[1], q[2], q[3], v.x, v.y, v.z)
    res.header = transform.header
    return res


def do_transform_pose(pose: Any, transform: Any) -> Any:
    """A geometry_msgs/PoseStamped in the transform's target frame."""
    (tx, ty, tz), (ax, ay, az, aw) = _parts(transform)
    p, o = pose.pose.position, pose.pose.orientation
    x, y, z = _rotate(ax, ay, az, aw, p.x, p.y, p.z)
    bx, by, bz, bw = o.x, o.y, o.z, o.w
    # both normalised, as KDL builds rotation matrices from them
    na = (ax * ax + ay * ay + az * az + aw * aw) ** 0.5
    nb = (bx * bx + by * by + bz * bz + bw * bw) ** 0.5
    ax, ay, az, aw = ax / na, ay / na, az / na, aw / na
    bx, by, bz, bw = bx / nb, by / nb, bz / nb, bw / nb
    q = _kdl_sign((aw * bx + ax * bw + ay * bz - az * by,
                   aw * by + ay * bw + az * bx - ax * bz,
                   aw * bz + az * bw + ax * by - ay * bx,
                   aw * bw - ax * bx - ay * by - az * bz))
    res = PoseStamped()
    res.pose.position.x, res.pose.position.y, res.pose.position.z = x + tx, y + ty, z + tz
    o = res.pose.orientation
    o.x, o.y, o.z, o.w = q
    res.header = transform.header
    return res


def do_transform_wrench(wrench: Any, transform: Any) -> Any:
    """A geometry_msgs/WrenchStamped: force and torque rotated into the target frame."""
    _, q = _parts(transform)
    res = WrenchStamped()
    for name in ("force", "torque"):
        v = getattr(wrench.wrench, name)
        out = getattr(res.wrench, name)
        out.x, out.y, out.z = _rotate(q[0], q[1], q[2], q[3], v.x, v.y, v.z)
    res.header = transform.header
    return res


def transform_to_kdl(t: Any) -> Any:
    """The PyKDL Frame of a geometry_msgs/TransformStamped (tf2_kdl's is this one)."""
    from minros.kdl import Frame, Rotation, Vector  # PyKDL only for the code that asks for it

    r, v = t.transform.rotation, t.transform.translation
    return Frame(Rotation.Quaternion(r.x, r.y, r.z, r.w), Vector(v.x, v.y, v.z))


def _register() -> None:
    convert = ConvertRegistration()
    for cls in (Vector3Stamped, PoseStamped, PointStamped):
        convert.add_to_msg(cls, to_msg_msg)
        convert.add_from_msg(cls, from_msg_msg)
    transforms = TransformRegistration()
    transforms.add(PointStamped, do_transform_point)
    transforms.add(Vector3Stamped, do_transform_vector3)
    transforms.add(PoseStamped, do_transform_pose)
    transforms.add(WrenchStamped, do_transform_wrench)


_register()

__all__ = ["do_transform_point", "do_transform_vector3", "do_transform_pose",
           "do_transform_wrench", "to_msg_msg", "from_msg_msg", "transform_to_kdl"]

