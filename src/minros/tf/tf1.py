"""ROS 1's first tf API (``import tf``) on top of the tf2 buffer, as Noetic's tf does.

Frame names may start with '/' here: tf1 strips it before asking tf2. Lookups return
``([x, y, z], [qx, qy, qz, qw])`` lists; ``transformPoint`` and friends return new stamped
messages in the target frame. ``waitForTransform`` needs the listener's thread (a
TransformListener), like in ROS.
"""

from __future__ import annotations

from typing import Any, List, Tuple

import numpy
import yaml

import minros

from . import transformations
from .broadcaster import TransformBroadcaster as _Tf2Broadcaster
from .buffer import Buffer
from .exceptions import TransformException
from .listener import TransformListener as _Tf2Listener


def strip_leading_slash(s: str) -> str:
    return s[1:] if s.startswith("/") else s


def xyz_to_mat44(pos: Any) -> numpy.ndarray:
    return transformations.translation_matrix((pos.x, pos.y, pos.z))


def xyzw_to_mat44(ori: Any) -> numpy.ndarray:
    return transformations.quaternion_matrix((ori.x, ori.y, ori.z, ori.w))


def _pair(msg: Any) -> Tuple[List[float], List[float]]:
    t, r = msg.transform.translation, msg.transform.rotation
    return [t.x, t.y, t.z], [r.x, r.y, r.z, r.w]


class Transformer:
    """A tf1 transformer: a tf2 buffer with tf1's method names and '/'-tolerant frames."""

    def __init__(self, interpolate: bool = True, cache_time: Any = None) -> None:
        self._buffer = Buffer(cache_time, debug=False)
        self._using_dedicated_thread = False

    def allFramesAsDot(self, current_time: Any = None) -> str:  # noqa: N802
        return self._buffer._allFramesAsDot(current_time)

    def allFramesAsString(self) -> str:  # noqa: N802
        return self._buffer.all_frames_as_string()

    def setTransform(self, transform: Any, authority: str = "default_authority") -> None:  # noqa: N802
        self._buffer.set_transform(transform, authority)

    def canTransform(self, target_frame: str, source_frame: str, time: Any) -> bool:  # noqa: N802
        return self._buffer.can_transform(strip_leading_slash(target_frame),
                                          strip_leading_slash(source_frame), time)

    def canTransformFull(self, target_frame: str, target_time: Any, source_frame: str,  # noqa: N802
                         source_time: Any, fixed_frame: str) -> bool:
        return self._buffer.can_transform_full(
            strip_leading_slash(target_frame), target_time, strip_leading_slash(source_frame),
            source_time, strip_leading_slash(fixed_frame))

    def _need_thread(self) -> None:
        if not self._using_dedicated_thread:
            raise TransformException("cannot wait for transform without a dedicated thread that "
                                     "listens to incoming TF messages")

    def waitForTransform(self, target_frame: str, source_frame: str, time: Any, timeout: Any,  # noqa: N802
                         polling_sleep_duration: Any = None) -> None:
        """Return when the transform is available; TransformException after ``timeout``."""
        self._need_thread()
        ok, error = self._buffer.can_transform(
            strip_leading_slash(target_frame), strip_leading_slash(source_frame), time, timeout,
            return_debug_tuple=True)
        if not ok:
            raise TransformException(
                error or f'no such transformation: "{source_frame}" -> "{target_frame}"')

    def waitForTransformFull(self, target_frame: str, target_time: Any, source_frame: str,  # noqa: N802
                             source_time: Any, fixed_frame: str, timeout: Any,
                             polling_sleep_duration: Any = None) -> None:
        self._need_thread()
        ok, error = self._buffer.can_transform_full(
            strip_leading_slash(target_frame), target_time, strip_leading_slash(source_frame),
            source_time, strip_leading_slash(fixed_frame), timeout, return_debug_tuple=True)
        if not ok:
            raise TransformException(
                error or f'no such transformation: "{source_frame}" -> "{target_frame}"')

    def chain(self, target_frame: str, target_time: Any, source_frame: str, source_time: Any,
              fixed_frame: str) -> List[str]:
        return self._buffer._chain(target_frame, target_time, source_frame, source_time,
                                   fixed_frame)

    def clear(self) -> None:
        self._buffer.clear()

    def frameExists(self, frame_id: str) -> bool:  # noqa: N802
        """Whether ``frame_id`` has a parent in the tree (a root frame does not count, as in
        ROS's tf)."""
        return frame_id in self.getFrameStrings()

    def getFrameStrings(self) -> List[str]:  # noqa: N802
        data = yaml.safe_load(self._buffer.all_frames_as_yaml()) or {}
        return list(data)

    def getLatestCommonTime(self, source_frame: str, dest_frame: str) -> Any:  # noqa: N802
        return self._buffer.get_latest_common_time(strip_leading_slash(source_frame),
                                                   strip_leading_slash(dest_frame))

    def lookupTransform(self, target_frame: str, source_frame: str,  # noqa: N802
                        time: Any) -> Tuple[List[float], List[float]]:
        """``([x, y, z], [qx, qy, qz, qw])`` of ``source_frame`` in ``target_frame``."""
        return _pair(self._buffer.lookup_transform(strip_leading_slash(target_frame),
                                                   strip_leading_slash(source_frame), time))

    def lookupTransformFull(self, target_frame: str, target_time: Any, source_frame: str,  # noqa: N802
                            source_time: Any, fixed_frame: str) -> Tuple[List[float], List[float]]:
        return _pair(self._buffer.lookup_transform_full(
            strip_leading_slash(target_frame), target_time, strip_leading_slash(source_frame),
            source_time, strip_leading_slash(fixed_frame)))

    def lookupTwist(self, tracking_frame: str, observation_frame: str, time: Any,  # noqa: N802
                    averaging_interval: Any) -> Tuple[Any, Any]:
        return self.lookupTwistFull(tracking_frame, observation_frame, observation_frame,
                                    (0, 0, 0), tracking_frame, time, averaging_interval)

    def lookupTwistFull(self, tracking_frame: str, observation_frame: str, reference_frame: str,  # noqa: N802
                        ref_point: Any, reference_point_frame: str, time: Any,
                        averaging_interval: Any) -> Tuple[Any, Any]:
        """(linear, angular) velocity of ``tracking_frame`` seen from ``observation_frame``,
        averaged over ``averaging_interval`` around ``time``, in ``reference_frame`` at the
        point ``ref_point`` of ``reference_point_frame``."""
        latest = self.getLatestCommonTime(observation_frame, tracking_frame)
        target_time = time or latest
        end = min(target_time + minros.Duration.from_sec(0.5 * averaging_interval.to_sec()), latest)
        start = max(minros.Time.from_sec(0.0001) + averaging_interval, end) - averaging_interval
        dt = (end - start).to_sec()
        start_tr, start_rt = self.lookupTransform(observation_frame, tracking_frame, start)
        end_tr, end_rt = self.lookupTransform(observation_frame, tracking_frame, end)
        d_rot = numpy.dot(numpy.linalg.inv(transformations.quaternion_matrix(start_rt)),
                          transformations.quaternion_matrix(end_rt))
        angle, axis, _ = transformations.rotation_from_matrix(d_rot)
        vel0 = numpy.subtract(end_tr, start_tr) / dt
        rot0 = numpy.asarray(axis) * angle / dt
        inv_tr, inv_rt = self.lookupTransform(reference_frame, tracking_frame, target_time)
        r_ref = transformations.quaternion_matrix(inv_rt)[:3, :3]
        rot = numpy.dot(r_ref, rot0)
        vel = numpy.dot(r_ref, vel0) + numpy.cross(inv_tr, rot)
        origin = numpy.array((inv_tr[0], inv_tr[1], inv_tr[2], 1.0))
        rp_tr, rp_rt = self.lookupTransform(reference_frame, reference_point_frame, target_time)
        m = numpy.dot(transformations.translation_matrix(rp_tr),
                      transformations.quaternion_matrix(rp_rt))
        delta = numpy.dot(m, origin) - origin
        # ROS's tf adds the dot product here (not the cross product a moved reference point
        # calls for); kept so that ported code gets the numbers it got under ROS
        vel += numpy.dot(rot, delta[:3])
        return (vel[0], vel[1], vel[2]), (rot[0], rot[1], rot[2])

    def setUsingDedicatedThread(self, value: bool) -> None:  # noqa: N802
        self._using_dedicated_thread = value

    def getTFPrefix(self) -> str:  # noqa: N802
        """tf2 has no tf_prefix: always empty."""
        return ""


class TransformerROS(Transformer):
    """Transformer plus transforms of geometry_msgs/sensor_msgs messages."""

    def asMatrix(self, target_frame: str, hdr: Any) -> numpy.ndarray:  # noqa: N802
        """The 4x4 matrix taking data stamped with ``hdr`` into ``target_frame``."""
        translation, rotation = self.lookupTransform(target_frame, hdr.frame_id, hdr.stamp)
        return self.fromTranslationRotation(translation, rotation)

    def fromTranslationRotation(self, translation: Any, rotation: Any) -> numpy.ndarray:  # noqa: N802
        return numpy.dot(transformations.translation_matrix(translation),
                         transformations.quaternion_matrix(rotation))

    def transformPoint(self, target_frame: str, ps: Any) -> Any:  # noqa: N802
        """A new geometry_msgs/PointStamped in ``target_frame``."""
        from geometry_msgs.msg import Point, PointStamped

        mat44 = self.asMatrix(target_frame, ps.header)
        xyz = numpy.dot(mat44, (ps.point.x, ps.point.y, ps.point.z, 1.0))[:3]
        r = PointStamped()
        r.header.stamp = ps.header.stamp
        r.header.frame_id = target_frame
        r.point = Point(*(float(v) for v in xyz))
        return r

    def transformVector3(self, target_frame: str, v3s: Any) -> Any:  # noqa: N802
        """A new geometry_msgs/Vector3Stamped in ``target_frame`` (rotation only)."""
        from geometry_msgs.msg import Vector3, Vector3Stamped

        mat44 = self.asMatrix(target_frame, v3s.header)
        xyz = numpy.dot(mat44[:3, :3], (v3s.vector.x, v3s.vector.y, v3s.vector.z))
        r = Vector3Stamped()
        r.header.stamp = v3s.header.stamp
        r.header.frame_id = target_frame
        r.vector = Vector3(*(float(v) for v in xyz))
        return r

    def transformQuaternion(self, target_frame: str, ps: Any) -> Any:  # noqa: N802
        """A new geometry_msgs/QuaternionStamped in ``target_frame``."""
        from geometry_msgs.msg import Quaternion, QuaternionStamped

        txpose = numpy.dot(self.asMatrix(target_frame, ps.header), xyzw_to_mat44(ps.quaternion))
        r = QuaternionStamped()
        r.header.stamp = ps.header.stamp
        r.header.frame_id = target_frame
        r.quaternion = Quaternion(*(float(v) for v in transformations.quaternion_from_matrix(txpose)))
        return r

    def transformPose(self, target_frame: str, ps: Any) -> Any:  # noqa: N802
        """A new geometry_msgs/PoseStamped in ``target_frame``."""
        from geometry_msgs.msg import Point, Pose, PoseStamped, Quaternion

        pose44 = numpy.dot(xyz_to_mat44(ps.pose.position), xyzw_to_mat44(ps.pose.orientation))
        txpose = numpy.dot(self.asMatrix(target_frame, ps.header), pose44)
        r = PoseStamped()
        r.header.stamp = ps.header.stamp
        r.header.frame_id = target_frame
        r.pose = Pose(Point(*(float(v) for v in txpose[:3, 3])),
                      Quaternion(*(float(v) for v in transformations.quaternion_from_matrix(txpose))))
        return r

    def transformPointCloud(self, target_frame: str, point_cloud: Any) -> Any:  # noqa: N802
        """A new sensor_msgs/PointCloud in ``target_frame`` (channels kept)."""
        from geometry_msgs.msg import Point
        from sensor_msgs.msg import PointCloud

        r = PointCloud()
        r.header.stamp = point_cloud.header.stamp
        r.header.frame_id = target_frame
        r.channels = point_cloud.channels
        mat44 = self.asMatrix(target_frame, point_cloud.header)
        if point_cloud.points:
            xyz1 = numpy.array([(p.x, p.y, p.z, 1.0) for p in point_cloud.points])
            out = numpy.dot(xyz1, mat44.T)[:, :3]
            r.points = [Point(float(x), float(y), float(z)) for x, y, z in out]
        return r


class TransformListener(TransformerROS):
    """A TransformerROS kept up to date from ``/tf`` and ``/tf_static``."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        TransformerROS.__init__(self, *args, **kwargs)
        self._listener = _Tf2Listener(self._buffer)
        self.setUsingDedicatedThread(True)


class TransformBroadcaster:
    """Send transforms on ``/tf`` the tf1 way: translation and rotation tuples."""

    def __init__(self, queue_size: int = 100) -> None:
        self.tf2_broadcaster = _Tf2Broadcaster()

    def sendTransform(self, translation: Any, rotation: Any, time: Any, child: str,  # noqa: N802
                      parent: str) -> None:
        """Broadcast the pose of frame ``child`` in frame ``parent``: translation (x, y, z),
        rotation (x, y, z, w), stamped ``time``."""
        from geometry_msgs.msg import TransformStamped

        t = TransformStamped()
        t.header.frame_id = parent
        t.header.stamp = time
        t.child_frame_id = child
        tr = t.transform.translation
        tr.x, tr.y, tr.z = float(translation[0]), float(translation[1]), float(translation[2])
        r = t.transform.rotation
        r.x, r.y, r.z, r.w = (float(rotation[0]), float(rotation[1]), float(rotation[2]),
                              float(rotation[3]))
        self.sendTransformMessage(t)

    def sendTransformMessage(self, transform: Any) -> None:  # noqa: N802
        """Broadcast a geometry_msgs/TransformStamped."""
        self.tf2_broadcaster.sendTransform([transform])


__all__ = ["Transformer", "TransformerROS", "TransformListener", "TransformBroadcaster",
           "strip_leading_slash", "xyz_to_mat44", "xyzw_to_mat44"]
