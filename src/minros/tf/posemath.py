"""tf_conversions.posemath: PyKDL Frames to and from the other forms of a pose.

``fromTf``/``toTf`` take and give the ``((x, y, z), (qx, qy, qz, qw))`` pairs of
``tf.TransformListener.lookupTransform``; ``fromMsg``/``toMsg`` a geometry_msgs/Pose;
``fromMatrix``/``toMatrix`` a 4x4 homogeneous numpy array; ``fromCameraParams`` OpenCV's
Rodrigues rotation vector and translation. Quaternions go through KDL's
``Rotation.Quaternion``/``GetQuaternion``, so a non-unit quaternion scales the matrix and the
sign of the quaternion returned is KDL's, as with ROS's module.
"""

from __future__ import annotations

from typing import Any, Sequence, Tuple

import numpy

from minros.kdl import Frame, Rotation, Vector

__all__ = ["fromTf", "toTf", "fromMsg", "toMsg", "fromMatrix", "toMatrix", "fromCameraParams"]


def fromTf(tf: Tuple[Sequence[float], Sequence[float]]) -> Frame:  # noqa: N802 (ROS's names)
    """The Frame of a ``(translation, quaternion)`` pair from ``tf``'s lookupTransform."""
    position, quaternion = tf
    x, y, z = position
    qx, qy, qz, qw = quaternion
    return Frame(Rotation.Quaternion(qx, qy, qz, qw), Vector(x, y, z))


def toTf(f: Frame) -> Tuple[Tuple[float, float, float], Tuple[float, float, float, float]]:  # noqa: N802
    """``((x, y, z), (qx, qy, qz, qw))`` of Frame ``f``."""
    p = f.p
    return (p[0], p[1], p[2]), f.M.GetQuaternion()


def fromMsg(p: Any) -> Frame:  # noqa: N802
    """The Frame of a geometry_msgs/Pose."""
    o, q = p.position, p.orientation
    return Frame(Rotation.Quaternion(q.x, q.y, q.z, q.w), Vector(o.x, o.y, o.z))


def toMsg(f: Frame) -> Any:  # noqa: N802
    """A geometry_msgs/Pose of Frame ``f``."""
    from geometry_msgs.msg import Pose

    pose = Pose()
    o, q = pose.position, pose.orientation
    q.x, q.y, q.z, q.w = f.M.GetQuaternion()
    o.x, o.y, o.z = f.p[0], f.p[1], f.p[2]
    return pose


def fromMatrix(m: Any) -> Frame:  # noqa: N802
    """The Frame of a 4x4 (or 3x4) homogeneous matrix: a numpy array or anything indexed
    ``m[i, j]``."""
    return Frame(Rotation(m[0, 0], m[0, 1], m[0, 2], m[1, 0], m[1, 1], m[1, 2],
                          m[2, 0], m[2, 1], m[2, 2]),
                 Vector(m[0, 3], m[1, 3], m[2, 3]))


def toMatrix(f: Frame) -> numpy.ndarray:  # noqa: N802
    """The 4x4 homogeneous matrix (float64 numpy array) of Frame ``f``."""
    out = numpy.zeros((4, 4))
    for i in range(3):
        for j in range(4):
            out[i, j] = f[i, j]
    out[3, 3] = 1.0
    return out


def fromCameraParams(cv: Any, rvec: Any, tvec: Any) -> Frame:  # noqa: N802
    """The Frame of an OpenCV pose estimate: Rodrigues vector ``rvec`` and translation
    ``tvec`` (3x1 each). ``cv`` is the OpenCV module: the old ``cv`` (whose ``Rodrigues2``
    ROS's function calls) or ``cv2``."""
    m = numpy.zeros((4, 4), dtype=numpy.float32)
    m[0, 3], m[1, 3], m[2, 3], m[3, 3] = tvec[0, 0], tvec[1, 0], tvec[2, 0], 1.0
    if hasattr(cv, "Rodrigues2"):
        cv.Rodrigues2(rvec, m[:3, :3])
    else:
        m[:3, :3] = cv.Rodrigues(numpy.asarray(rvec, dtype=numpy.float64).reshape(3, 1))[0]
    return fromMatrix(m)
