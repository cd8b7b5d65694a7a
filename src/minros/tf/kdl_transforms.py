"""tf2_kdl: apply a geometry_msgs/TransformStamped to PyKDL Vectors, Frames, Twists and
Wrenches, and convert a PyKDL Vector to and from geometry_msgs/PointStamped.

Importing the module registers the conversions with tf2_ros, as ROS's does, so that
``buffer.transform(tf2_ros.Stamped(PyKDL.Vector(...), stamp, frame), target)`` works. The
stamped object carries a ``header`` attribute (minros's PyKDL types keep one for this);
Debian's pybind11 PyKDL has no room for it, so there ``Stamped`` and every ``do_transform_*``
of tf2_kdl fail with AttributeError.
"""

from __future__ import annotations

from typing import Any

from minros.kdl import Frame, Twist, Vector, Wrench

from .buffer import ConvertRegistration, Stamped, TransformRegistration
from .geometry import transform_to_kdl

__all__ = ["transform_to_kdl", "do_transform_vector", "to_msg_vector", "from_msg_vector",
           "convert_vector", "do_transform_frame", "do_transform_twist", "do_transform_wrench"]


def _apply(obj: Any, transform: Any) -> Any:
    res = transform_to_kdl(transform) * obj
    res.header = transform.header
    return res


def do_transform_vector(vector: Vector, transform: Any) -> Vector:
    """The point ``vector`` in the transform's target frame (rotated and translated)."""
    return _apply(vector, transform)


def do_transform_frame(frame: Frame, transform: Any) -> Frame:
    return _apply(frame, transform)


def do_transform_twist(twist: Twist, transform: Any) -> Twist:
    return _apply(twist, transform)


def do_transform_wrench(wrench: Wrench, transform: Any) -> Wrench:
    return _apply(wrench, transform)


def to_msg_vector(vector: Vector) -> Any:
    """A geometry_msgs/PointStamped of a stamped PyKDL Vector."""
    from geometry_msgs.msg import PointStamped

    msg = PointStamped()
    msg.header = vector.header
    msg.point.x, msg.point.y, msg.point.z = vector[0], vector[1], vector[2]
    return msg


def from_msg_vector(msg: Any) -> Vector:
    """A stamped PyKDL Vector of a geometry_msgs/PointStamped."""
    point = msg.point
    return Stamped(Vector(point.x, point.y, point.z), msg.header.stamp, msg.header.frame_id)


def convert_vector(vector: Vector) -> Vector:
    """A stamped copy of a stamped PyKDL Vector."""
    return Stamped(Vector(vector), vector.header.stamp, vector.header.frame_id)


def _register() -> None:
    transforms, converts = TransformRegistration(), ConvertRegistration()
    transforms.add(Vector, do_transform_vector)
    transforms.add(Frame, do_transform_frame)
    transforms.add(Twist, do_transform_twist)
    transforms.add(Wrench, do_transform_wrench)
    converts.add_to_msg(Vector, to_msg_vector)
    converts.add_from_msg(Vector, from_msg_vector)
    converts.add_convert((Vector, Vector), convert_vector)


_register()
