"""tf2_sensor_msgs: apply a geometry_msgs/TransformStamped to a sensor_msgs/PointCloud2.

``do_transform_cloud`` moves the first three fields (by offset: x, y, z in every cloud ROS
makes) by the transform and keeps the others, returning the cloud ROS's function returns: one
row of points (an organized cloud comes back flat), packed without padding after the last
field, the transform's header. Where ROS converts point by point through Python tuples and
PyKDL, this works on a numpy view of the whole cloud, with the same float64 arithmetic (so the
same float32 results); a layout numpy cannot view falls back to reading point by point.
Importing the module registers the function with tf2_ros, as ROS's does.
"""

from __future__ import annotations

import struct
from typing import Any

import numpy

from minros.kdl import Frame, Rotation, Vector
from minros.msgs import get_message_class

# the cloud layout as sensor_msgs.point_cloud2 reads and writes it (its own helpers, so the two
# modules agree on padding, byte order and the fields a cloud can hold)
from minros.point_cloud2 import _dtype, _layout, _records, create_cloud, read_points

from .buffer import ConvertRegistration, TransformRegistration

__all__ = ["to_msg_msg", "from_msg_msg", "transform_to_kdl", "do_transform_cloud"]


def to_msg_msg(msg: Any) -> Any:
    return msg


def from_msg_msg(msg: Any) -> Any:
    return msg


def transform_to_kdl(t: Any) -> Frame:
    """The PyKDL Frame of a geometry_msgs/TransformStamped."""
    r, v = t.transform.rotation, t.transform.translation
    return Frame(Rotation.Quaternion(r.x, r.y, r.z, r.w), Vector(v.x, v.y, v.z))


def do_transform_cloud(cloud: Any, transform: Any) -> Any:
    """``cloud`` with its points in the transform's target frame."""
    frame = transform_to_kdl(transform)
    fmt, items = _layout(cloud.is_bigendian, cloud.fields)
    size = struct.calcsize(fmt)
    if len(items) < 3 or any(code not in "fd" for code, _ in items[:3]):
        kinds = ", ".join(f"{f.name} ({f.datatype})" for f in sorted(cloud.fields, key=lambda f: f.offset))
        raise ValueError("do_transform_cloud moves the first three fields by offset, which must "
                         f"be float32 or float64 (PointField datatype 7 or 8); this cloud has {kinds}")
    records = _records(cloud, items, size)
    if records is None:  # a layout numpy cannot view: ROS's reading and its errors
        return _transform_point_by_point(cloud, transform, frame)
    m0, m1, m2, m3, m4, m5, m6, m7, m8 = (frame.M[i, j] for i in range(3) for j in range(3))
    px, py, pz = frame.p[0], frame.p[1], frame.p[2]
    x, y, z = (records[f"f{i}"].astype(numpy.float64) for i in range(3))
    out = numpy.zeros(records.shape[0], dtype=_dtype(False, items, size))
    for i in range(3, len(items)):
        out[f"f{i}"] = records[f"f{i}"]
    out["f0"] = m0 * x + m1 * y + m2 * z + px
    out["f1"] = m3 * x + m4 * y + m5 * z + py
    out["f2"] = m6 * x + m7 * y + m8 * z + pz
    count = out.shape[0]
    return get_message_class("sensor_msgs/PointCloud2")(
        header=transform.header, height=1, width=count, is_dense=False, is_bigendian=False,
        fields=cloud.fields, point_step=size, row_step=size * count, data=out.tobytes())


def _transform_point_by_point(cloud: Any, transform: Any, frame: Frame) -> Any:
    points = []
    for point in read_points(cloud):
        moved = frame * Vector(point[0], point[1], point[2])
        points.append((moved[0], moved[1], moved[2]) + tuple(point[3:]))
    return create_cloud(transform.header, cloud.fields, points)


def _register() -> None:
    cloud = get_message_class("sensor_msgs/PointCloud2")
    ConvertRegistration().add_to_msg(cloud, to_msg_msg)
    ConvertRegistration().add_from_msg(cloud, from_msg_msg)
    TransformRegistration().add(cloud, do_transform_cloud)


_register()
