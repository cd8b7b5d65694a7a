"""tf_conversions, tf2_kdl, tf2_sensor_msgs, laser_geometry and image_geometry on their own:
round trips, a buffer transforming PyKDL types, clouds and scans with known answers, camera
models against their own inverses. (Debian's numbers: tests/interop/test_geometry_libs_interop.py.)"""

from __future__ import annotations

import math
import struct
import warnings

import numpy as np
import pytest

import PyKDL as K
import rospy
import tf2_geometry_msgs  # noqa: F401 (registers PointStamped, as in ROS)
import tf2_kdl
import tf2_ros
import tf2_sensor_msgs
import tf_conversions.posemath as pm
from geometry_msgs.msg import PointStamped, Pose, TransformStamped
from image_geometry import PinholeCameraModel, StereoCameraModel
from laser_geometry import LaserProjection
from sensor_msgs import point_cloud2
from sensor_msgs.msg import CameraInfo, LaserScan, PointCloud2, PointField
from std_msgs.msg import Header


def transform(parent: str, child: str, xyz, rpy, secs: int = 10) -> TransformStamped:
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id, t.header.stamp = parent, child, rospy.Time(secs)
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    q = t.transform.rotation
    q.x, q.y, q.z, q.w = K.Rotation.RPY(*rpy).GetQuaternion()
    return t


# ------------------------------------------------------------------------ posemath

def test_posemath_round_trips():
    f = K.Frame(K.Rotation.RPY(0.3, -0.4, 2.0), K.Vector(1, -2, 0.5))
    assert K.Equal(pm.fromMsg(pm.toMsg(f)), f, 1e-12)
    assert K.Equal(pm.fromTf(pm.toTf(f)), f, 1e-12)
    m = pm.toMatrix(f)
    assert m.shape == (4, 4) and m.dtype == np.float64 and list(m[3]) == [0, 0, 0, 1]
    assert K.Equal(pm.fromMatrix(m), f, 1e-12)
    assert np.allclose(m[:3, 3], [1, -2, 0.5])
    pose = pm.toMsg(f)
    assert isinstance(pose, Pose) and pose.orientation.w > 0
    # ROS's module offers PyKDL's names and tf's
    assert pm.Frame is K.Frame and hasattr(pm, "transformations")


def test_from_camera_params_accepts_cv2_and_the_old_cv_api():
    import cv2

    rvec = np.array([[0.1], [-0.2], [0.3]])
    tvec = np.array([[1.0], [2.0], [3.0]])
    expected = K.Rotation.Rot(K.Vector(0.1, -0.2, 0.3), math.sqrt(0.14))
    f = pm.fromCameraParams(cv2, rvec, tvec)
    assert K.Equal(f.M, expected, 1e-6) and K.Equal(f.p, K.Vector(1, 2, 3), 1e-6)

    class OldCv:  # the cv module ROS's function was written for: Rodrigues2(src, dst)
        @staticmethod
        def Rodrigues2(src, dst):  # noqa: N802
            dst[:] = cv2.Rodrigues(np.asarray(src, dtype=np.float64))[0]

    assert K.Equal(pm.fromCameraParams(OldCv, rvec, tvec), f, 1e-12)


# ------------------------------------------------------------------------- tf2_kdl

def test_a_buffer_transforms_stamped_kdl_types():
    buf = tf2_ros.Buffer(debug=False)
    buf.set_transform(transform("map", "base", (1, 0, 0), (0, 0, math.pi / 2)), "test")
    stamped = tf2_ros.Stamped(K.Vector(1, 0, 0), rospy.Time(10), "base")
    moved = buf.transform(stamped, "map")
    assert K.Equal(moved, K.Vector(1, 1, 0), 1e-12) and moved.header.frame_id == "map"
    frame = buf.transform(tf2_ros.Stamped(K.Frame(K.Vector(1, 0, 0)), rospy.Time(10), "base"), "map")
    assert K.Equal(frame.p, K.Vector(1, 1, 0), 1e-12)
    twist = buf.transform(tf2_ros.Stamped(K.Twist(K.Vector(1, 0, 0), K.Vector(0, 0, 1)),
                                          rospy.Time(10), "base"), "map")
    assert K.Equal(twist.rot, K.Vector(0, 0, 1), 1e-12)
    assert K.Equal(twist.vel, K.Vector(0, 1, 0) + K.Vector(1, 0, 0) * K.Vector(0, 0, 1), 1e-12)
    wrench = tf2_kdl.do_transform_wrench(K.Wrench(K.Vector(1, 0, 0), K.Vector()),
                                         transform("map", "base", (0, 0, 0), (0, 0, math.pi)))
    assert K.Equal(wrench.force, K.Vector(-1, 0, 0), 1e-12)


def test_kdl_vectors_convert_to_and_from_point_stamped():
    point = PointStamped()
    point.header.frame_id, point.point.x, point.point.y, point.point.z = "odom", 1.0, 2.0, 3.0
    vector = tf2_ros.convert(point, K.Vector)
    assert vector == K.Vector(1, 2, 3) and vector.header.frame_id == "odom"
    back = tf2_ros.convert(vector, PointStamped)
    assert (back.point.x, back.point.y, back.point.z, back.header.frame_id) == (1, 2, 3, "odom")
    copied = tf2_ros.convert(vector, K.Vector)
    assert copied is not vector and copied == vector and copied.header.frame_id == "odom"


# ------------------------------------------------------------------ tf2_sensor_msgs

FIELDS = [PointField("x", 0, PointField.FLOAT32, 1), PointField("y", 4, PointField.FLOAT32, 1),
          PointField("z", 8, PointField.FLOAT32, 1), PointField("ring", 12, PointField.UINT16, 1),
          PointField("intensity", 16, PointField.FLOAT32, 1)]


def test_a_cloud_moves_its_points_and_keeps_the_other_fields():
    points = [(1.0, 0.0, 0.0, 3, 0.5), (0.0, 2.0, 0.0, 7, 1.5), (math.nan, 0.0, 1.0, 9, 2.5)]
    cloud = point_cloud2.create_cloud(Header(frame_id="lidar"), FIELDS, points)
    t = transform("map", "lidar", (10, 0, 0), (0, 0, math.pi / 2))
    moved = tf2_sensor_msgs.do_transform_cloud(cloud, t)
    assert moved.header.frame_id == "map" and moved.width == 3 and moved.height == 1
    out = list(point_cloud2.read_points(moved))
    assert out[0][:3] == pytest.approx((10.0, 1.0, 0.0), abs=1e-6)
    assert out[1][:3] == pytest.approx((8.0, 0.0, 0.0), abs=1e-6)
    assert all(math.isnan(c) for c in out[2][:3])  # a NaN coordinate spreads through the rotation
    assert [p[3:] for p in out] == [(3, 0.5), (7, 1.5), (9, 2.5)]
    # the registration: tf2_ros's buffer does it too
    buf = tf2_ros.Buffer(debug=False)
    buf.set_transform(t, "test")
    cloud.header.stamp = rospy.Time(10)
    assert bytes(buf.transform(cloud, "map").data) == bytes(moved.data)


def test_organized_and_big_endian_clouds_come_back_flat_and_little_endian():
    points = [(float(i), float(-i), 0.5 * i, i, float(i)) for i in range(6)]
    cloud = point_cloud2.create_cloud(Header(frame_id="cam"), FIELDS, points)
    cloud.height, cloud.width, cloud.row_step = 2, 3, cloud.point_step * 3
    big = PointCloud2(header=cloud.header, height=2, width=3, fields=FIELDS, is_bigendian=True,
                      point_step=cloud.point_step, row_step=cloud.row_step, is_dense=False,
                      data=b"".join(struct.pack(">fffHxxf", *p) for p in points))
    t = transform("map", "cam", (0, 0, 1), (0, 0, 0))
    for source in (cloud, big):
        moved = tf2_sensor_msgs.do_transform_cloud(source, t)
        assert (moved.height, moved.width, moved.is_bigendian) == (1, 6, False)
        assert [p[2] for p in point_cloud2.read_points(moved)] == pytest.approx(
            [1 + 0.5 * i for i in range(6)])


def test_clouds_without_float_coordinates_are_refused_clearly():
    fields = [PointField("x", 0, PointField.INT32, 1), PointField("y", 4, PointField.INT32, 1),
              PointField("z", 8, PointField.INT32, 1)]
    cloud = point_cloud2.create_cloud(Header(), fields, [(1, 2, 3)])
    with pytest.raises(ValueError, match="must be float32 or float64"):
        tf2_sensor_msgs.do_transform_cloud(cloud, transform("m", "c", (1, 1, 1), (0, 0, 0)))


def test_a_cloud_numpy_cannot_view_is_read_point_by_point():
    # a field past point_step: numpy cannot view it; ROS's struct reading still can
    fields = [PointField("x", 0, PointField.FLOAT32, 1), PointField("y", 4, PointField.FLOAT32, 1),
              PointField("z", 8, PointField.FLOAT32, 1)]
    data = struct.pack("<fffff", 1, 2, 3, 4, 5)
    cloud = PointCloud2(height=1, width=2, fields=fields, point_step=8, row_step=16, data=data)
    moved = tf2_sensor_msgs.do_transform_cloud(cloud, transform("m", "c", (1, 1, 1), (0, 0, 0)))
    assert list(point_cloud2.read_points(moved)) == [(2.0, 3.0, 4.0), (4.0, 5.0, 6.0)]


# ------------------------------------------------------------------- laser_geometry

def scan(ranges, intensities=()):
    s = LaserScan()
    s.header.frame_id = "laser"
    s.angle_min, s.angle_increment = -math.pi / 2, math.pi / 2
    s.angle_max = s.angle_min + s.angle_increment * (len(ranges) - 1)
    s.range_min, s.range_max, s.time_increment = 0.1, 10.0, 0.01
    s.ranges, s.intensities = list(ranges), list(intensities)
    return s


def test_a_scan_projects_to_points_and_channels():
    s = scan([1.0, 2.0, math.inf, 0.05, 3.0], [10, 20, 30, 40, 50])
    cloud = LaserProjection().projectLaser(s, channel_options=0x1F)
    names = [f.name for f in cloud.fields]
    assert names == ["x", "y", "z", "intensity", "index", "distances", "stamps", "vp_x", "vp_y", "vp_z"]
    assert cloud.point_step == 40 and cloud.width == 3 and cloud.header.frame_id == "laser"
    points = list(point_cloud2.read_points(cloud))
    assert points[0][:2] == pytest.approx((0.0, -1.0), abs=1e-6)
    assert points[1][:2] == pytest.approx((2.0, 0.0), abs=1e-6)
    assert points[2][:2] == pytest.approx((0.0, -3.0), abs=1e-6)  # angle -pi/2 + 2 pi
    assert [p[4] for p in points] == [0, 1, 4] and [p[3] for p in points] == [10, 20, 50]
    assert [p[6] for p in points] == pytest.approx([0.0, 0.01, 0.04])
    default = LaserProjection().projectLaser(s, 2.5)
    assert [f.name for f in default.fields] == ["x", "y", "z", "intensity", "index"]
    assert default.width == 2  # 3.0 is beyond the cutoff


def test_projection_reuses_its_angles_and_names_a_short_intensity_list():
    projection = LaserProjection()
    first = projection.projectLaser(scan([1.0, 1.0, 1.0]))
    again = projection.projectLaser(scan([1.0, 1.0, 1.0]))
    assert bytes(first.data) == bytes(again.data)
    with pytest.raises(IndexError, match="intensities"):
        projection.projectLaser(scan([1.0, 1.0, 1.0], [5.0]))


# ------------------------------------------------------------------- image_geometry

def camera(tx: float = 0.0) -> CameraInfo:
    info = CameraInfo()
    info.header.frame_id = "cam"
    info.width, info.height = 64, 48
    info.K = [50.0, 0, 32, 0, 55.0, 24, 0, 0, 1]
    info.D = [0.1, -0.15, 0.01, 0.005, 0.05]
    info.R = [1.0, 0, 0, 0, 1, 0, 0, 0, 1]
    info.P = [52.0, 0, 31, tx * 52.0, 0, 52.0, 25, 0, 0, 0, 1, 0]
    return info


def test_pinhole_projection_and_its_inverse():
    model = PinholeCameraModel()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy.matrix's constructor warns: not used
        model.fromCameraInfo(camera())
    assert isinstance(model.P, np.matrix) and model.P.shape == (3, 4)
    u, v = model.project3dToPixel((0.2, -0.1, 2.0))
    assert (u, v) == pytest.approx((31 + 52 * 0.1, 25 - 52 * 0.05))
    ray = model.projectPixelTo3dRay((u, v))
    assert np.allclose(np.array(ray) * math.sqrt(0.2 ** 2 + 0.1 ** 2 + 4), (0.2, -0.1, 2.0))
    assert model.getDeltaX(model.getDeltaU(0.3, 2.0), 2.0) == pytest.approx(0.3)
    assert model.getDeltaU(0.3, 0) == math.inf
    assert model.fovX() == pytest.approx(2 * math.atan(64 / 104))
    assert model.tfFrame() == "cam" and model.fullResolution() == (64, 48)
    # binning and ROI shift the principal point and scale the focal lengths
    info = camera()
    info.binning_x, info.binning_y = 2, 2
    info.roi.x_offset, info.roi.y_offset, info.roi.width, info.roi.height = 4, 2, 40, 30
    model.fromCameraInfo(info)
    assert (model.fx(), model.cx(), model.cy()) == pytest.approx((26.0, 13.5, 11.5))
    assert model.fullProjectionMatrix()[0, 0] == 52.0


def test_rectification_undoes_the_distortion_model():
    import cv2

    model = PinholeCameraModel()
    model.fromCameraInfo(camera())
    # rectifyPoint's normalised undistortion, projected back through the distortion model,
    # lands on the raw pixel
    nx, ny = cv2.undistortPoints(np.array([[[20.0, 15.0]]]), model.K, model.D)[0, 0]
    back = cv2.projectPoints(np.array([[nx, ny, 1.0]]), np.zeros(3), np.zeros(3),
                             np.asarray(model.K), np.asarray(model.D))[0][0, 0]
    assert back == pytest.approx((20.0, 15.0), abs=1e-3)
    rectified = model.rectifyPoint((20.0, 15.0))
    assert rectified.shape == (2,)
    raw = np.tile(np.arange(64, dtype=np.uint8), (48, 1))
    out = np.zeros_like(raw)
    model.rectifyImage(raw, out)
    maps = model.mapx
    model.rectifyImage(raw, out)
    assert model.mapx is maps  # computed once per CameraInfo
    assert out.any() and out.shape == raw.shape


def test_stereo_depth_and_disparity_are_inverse():
    stereo = StereoCameraModel()
    stereo.fromCameraInfo(camera(), camera(tx=-0.1))
    assert stereo.getZ(stereo.getDisparity(2.0)) == pytest.approx(2.0)
    x, y, z = stereo.projectPixelTo3d((40.0, 30.0), stereo.getDisparity(2.0))
    assert z == pytest.approx(2.0)
    left, right = stereo.project3dToPixel((x, y, z))
    assert left == pytest.approx((40.0, 30.0))
    assert left[0] - right[0] == pytest.approx(stereo.getDisparity(2.0))
    assert stereo.projectPixelTo3d((1.0, 1.0), 0.0) == (0.0, 0.0, 0.0)
    assert stereo.tfFrame() == "cam"


def test_tf2_geometry_msgs_transform_to_kdl_gives_a_pykdl_frame():
    import PyKDL
    import tf2_kdl
    from geometry_msgs.msg import TransformStamped

    t = TransformStamped()
    t.transform.translation.x, t.transform.translation.z = 2.0, -1.0
    t.transform.rotation.z = t.transform.rotation.w = 0.5 ** 0.5  # a quarter turn about z
    frame = tf2_geometry_msgs.transform_to_kdl(t)
    assert isinstance(frame, PyKDL.Frame)
    moved = frame * PyKDL.Vector(1, 0, 0)
    assert [round(moved[i], 9) for i in range(3)] == [2.0, 1.0, -1.0]
    assert tf2_kdl.transform_to_kdl is tf2_geometry_msgs.transform_to_kdl
