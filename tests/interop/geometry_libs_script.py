"""One script, run under Debian's interpreter and under minros's: tf_conversions, tf2_kdl,
tf2_sensor_msgs, laser_geometry and image_geometry on random inputs (seeded by argv[1]),
printing a JSON object of plain results that test_geometry_libs_interop.py compares.

Nothing here may depend on which side runs it: the inputs come from random.Random(seed).
"""

import hashlib
import json
import math
import random
import sys

import numpy as np

import PyKDL
import rospy
import tf2_kdl
import tf2_ros
import tf2_sensor_msgs
import tf_conversions
import tf_conversions.posemath as pm
from geometry_msgs.msg import Pose, TransformStamped
from image_geometry import PinholeCameraModel, StereoCameraModel
from laser_geometry import LaserProjection
from sensor_msgs import point_cloud2
from sensor_msgs.msg import CameraInfo, LaserScan, PointField
from std_msgs.msg import Header

rnd = random.Random(int(sys.argv[1]))
out = {}


def frame_numbers(f):
    return [f[i, j] for i in range(3) for j in range(4)]


def unit_quaternion():
    q = [rnd.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(c * c for c in q))
    return [c / n for c in q]


def error(call, *args):
    try:
        call(*args)
    except Exception as exc:
        return type(exc).__name__
    return None


# ---------------------------------------------------------------- tf_conversions.posemath
poses = []
for _ in range(20):
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = (rnd.uniform(-5, 5) for _ in range(3))
    q = unit_quaternion()
    if rnd.random() < 0.3:
        q = [c * rnd.uniform(0.5, 2) for c in q]  # not normalised: KDL scales the matrix
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = q
    f = pm.fromMsg(pose)
    msg = pm.toMsg(f)
    tf_pair = pm.toTf(f)
    matrix = pm.toMatrix(f)
    poses.append({
        "fromMsg": frame_numbers(f),
        "toMsg": [msg.position.x, msg.position.y, msg.position.z, msg.orientation.x,
                  msg.orientation.y, msg.orientation.z, msg.orientation.w],
        "toTf": [list(tf_pair[0]), list(tf_pair[1])],
        "fromTf": frame_numbers(pm.fromTf(tf_pair)),
        "toMatrix": matrix.tolist(), "matrix_dtype": str(matrix.dtype),
        "fromMatrix": frame_numbers(pm.fromMatrix(matrix)),
        "compose": frame_numbers(pm.fromMsg(pose) * pm.fromTf(tf_pair)),
    })
out["posemath"] = poses
out["posemath_names"] = sorted(n for n in dir(tf_conversions) if not n.startswith("_")
                               and n != "absolute_import")

# ----------------------------------------------------------------------------- tf2_kdl
kdl = []
for _ in range(15):
    t = TransformStamped()
    t.header.frame_id, t.header.stamp, t.child_frame_id = "map", rospy.Time(5, 7), "base"
    tr, rot = t.transform.translation, t.transform.rotation
    tr.x, tr.y, tr.z = (rnd.uniform(-3, 3) for _ in range(3))
    rot.x, rot.y, rot.z, rot.w = unit_quaternion()
    frame = tf2_kdl.transform_to_kdl(t)
    v = PyKDL.Vector(*(rnd.uniform(-2, 2) for _ in range(3)))
    g = PyKDL.Frame(PyKDL.Rotation.RPY(*(rnd.uniform(-3, 3) for _ in range(3))), v)
    tw = PyKDL.Twist(v, PyKDL.Vector(*(rnd.uniform(-2, 2) for _ in range(3))))
    wr = PyKDL.Wrench(v, PyKDL.Vector(*(rnd.uniform(-2, 2) for _ in range(3))))
    kdl.append({
        "transform_to_kdl": frame_numbers(frame),
        # what do_transform_* compute (on Debian they then fail to attach the header)
        "vector": list(frame * v), "frame": frame_numbers(frame * g),
        "twist": [(frame * tw)[i] for i in range(6)], "wrench": [(frame * wr)[i] for i in range(6)],
        "do_transform_vector": error(tf2_kdl.do_transform_vector, v, t),
        "stamped": error(tf2_ros.Stamped, PyKDL.Vector(v), rospy.Time(1), "a"),
    })
out["tf2_kdl"] = kdl

# --------------------------------------------------------------------- tf2_sensor_msgs
clouds = []
layouts = [
    [("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1)],
    [("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1), ("rgb", 16, 7, 1)],
    [("x", 0, 8, 1), ("y", 8, 8, 1), ("z", 16, 8, 1), ("intensity", 24, 7, 1), ("ring", 28, 4, 1)],
    [("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1), ("normal", 12, 7, 3), ("label", 24, 2, 1)],
]
for layout in layouts:
    for height in (1, 3):
        fields = [PointField(name, offset, datatype, count) for name, offset, datatype, count in layout]
        width = rnd.randint(0, 40)
        points = []
        for _ in range(width * height):
            point = []
            for _name, _, datatype, count in layout:
                for _ in range(count):
                    if datatype in (7, 8):
                        value = rnd.uniform(-50, 50)
                        point.append(float("nan") if rnd.random() < 0.05 else value)
                    else:
                        point.append(rnd.randint(0, 200))
            points.append(point)
        cloud = point_cloud2.create_cloud(Header(frame_id="lidar"), fields, points)
        cloud.height, cloud.width = height, width
        cloud.row_step = cloud.point_step * width
        t = TransformStamped()
        t.header.frame_id, t.header.stamp = "map", rospy.Time(3, 9)
        tr, rot = t.transform.translation, t.transform.rotation
        tr.x, tr.y, tr.z = (rnd.uniform(-3, 3) for _ in range(3))
        rot.x, rot.y, rot.z, rot.w = unit_quaternion()
        moved = tf2_sensor_msgs.do_transform_cloud(cloud, t)
        clouds.append({
            "header": [moved.header.frame_id, moved.header.stamp.secs, moved.header.stamp.nsecs],
            "shape": [moved.height, moved.width, moved.point_step, moved.row_step,
                      moved.is_bigendian, moved.is_dense],
            "fields": [[f.name, f.offset, f.datatype, f.count] for f in moved.fields],
            "data": bytes(moved.data).hex(),
        })
out["tf2_sensor_msgs"] = clouds

# ----------------------------------------------------------------------- laser_geometry
scans = []
projection = LaserProjection()
for _ in range(12):
    scan = LaserScan()
    scan.header.frame_id, scan.header.stamp = "laser", rospy.Time(7, 11)
    n = rnd.choice([0, 1, 5, 90, 360])
    scan.angle_min = rnd.uniform(-3.1, 0)
    scan.angle_increment = rnd.uniform(0.001, 0.05)
    scan.angle_max = scan.angle_min + scan.angle_increment * max(n - 1, 0)
    scan.time_increment = rnd.uniform(0, 1e-4)
    scan.range_min, scan.range_max = 0.1, rnd.uniform(5, 30)
    odd = [None, float("inf"), float("nan"), 0.05, scan.range_max]
    scan.ranges = []
    for _ in range(n):
        value = rnd.choice(odd) if rnd.random() < 0.2 else rnd.uniform(0.1, 30)
        scan.ranges.append(rnd.uniform(0, 35) if value is None else value)
    # the message holds float32: round through it as the wire does
    scan.ranges = np.array(scan.ranges, dtype=np.float32).tolist()
    scan.intensities = (np.array([rnd.uniform(0, 1000) for _ in range(n)], dtype=np.float32).tolist()
                        if rnd.random() < 0.7 else [])
    scan.angle_min, scan.angle_max, scan.angle_increment, scan.time_increment, scan.range_max = (
        float(np.float32(x)) for x in (scan.angle_min, scan.angle_max, scan.angle_increment,
                                       scan.time_increment, scan.range_max))
    for options, cutoff in ((LaserProjection.ChannelOption.DEFAULT, -1.0), (0x1F, 10.0),
                            (LaserProjection.ChannelOption.NONE, 50.0),
                            (LaserProjection.ChannelOption.DISTANCE | 0x08, 3.0)):
        cloud = projection.projectLaser(scan, cutoff, options)
        scans.append({
            "header": [cloud.header.frame_id, cloud.header.stamp.secs],
            "shape": [cloud.height, cloud.width, cloud.point_step, cloud.row_step,
                      cloud.is_bigendian, cloud.is_dense],
            "fields": [[f.name, f.offset, f.datatype, f.count] for f in cloud.fields],
            "data": bytes(cloud.data).hex(),
        })
out["laser_geometry"] = scans
out["laser_constants"] = [LaserProjection.LASER_SCAN_INVALID, LaserProjection.LASER_SCAN_MIN_RANGE,
                          LaserProjection.LASER_SCAN_MAX_RANGE,
                          LaserProjection.ChannelOption.DEFAULT,
                          LaserProjection.ChannelOption.VIEWPOINT]

# ----------------------------------------------------------------------- image_geometry


def camera_info(tx=0.0):
    info = CameraInfo()
    info.header.frame_id = "camera"
    info.width, info.height = rnd.choice([(64, 48), (80, 60)])
    fx, fy = rnd.uniform(40, 90), rnd.uniform(40, 90)
    cx, cy = info.width / 2 + rnd.uniform(-5, 5), info.height / 2 + rnd.uniform(-5, 5)
    info.K = [fx, 0, cx, 0, fy, cy, 0, 0, 1]
    info.D = ([rnd.uniform(-0.2, 0.2) for _ in range(5)] if rnd.random() < 0.8 else [])
    info.distortion_model = "plumb_bob"
    r = PyKDL.Rotation.RPY(*(rnd.uniform(-0.05, 0.05) for _ in range(3)))
    info.R = [r[i, j] for i in range(3) for j in range(3)]
    pfx, pfy = fx * rnd.uniform(0.9, 1.1), fy * rnd.uniform(0.9, 1.1)
    info.P = [pfx, 0, cx + rnd.uniform(-2, 2), tx * pfx, 0, pfy, cy + rnd.uniform(-2, 2), 0, 0, 0, 1, 0]
    info.binning_x, info.binning_y = rnd.choice([(0, 0), (1, 1), (2, 2), (2, 1)])
    if rnd.random() < 0.3:
        info.roi.x_offset, info.roi.y_offset = rnd.randint(0, 8), rnd.randint(0, 8)
        info.roi.width, info.roi.height = info.width - 16, info.height - 16
    return info


def matrix(m):
    return None if m is None else np.asarray(m).tolist()


cameras = []
for _ in range(10):
    model = PinholeCameraModel()
    model.fromCameraInfo(camera_info())
    point = [rnd.uniform(-1, 1), rnd.uniform(-1, 1), rnd.uniform(0.5, 3)]
    uv = [rnd.uniform(0, 60), rnd.uniform(0, 45)]
    raw = np.array([[rnd.randint(0, 255) for _ in range(model.width)]
                    for _ in range(model.height)], dtype=np.uint8)
    rectified = np.zeros_like(raw)
    model.rectifyImage(raw, rectified)
    cameras.append({
        "K": matrix(model.K), "D": matrix(model.D), "R": matrix(model.R), "P": matrix(model.P),
        "full": [matrix(model.fullIntrinsicMatrix()), matrix(model.fullProjectionMatrix())],
        "kinds": [type(model.K).__name__, type(model.P).__name__],
        "scalars": [model.cx(), model.cy(), model.fx(), model.fy(), model.Tx(), model.Ty(),
                    model.fovX(), model.fovY(), model.tfFrame(), list(model.fullResolution()),
                    model.binning_x, model.binning_y],
        "roi": [model.raw_roi.x_offset, model.raw_roi.y_offset, model.raw_roi.width,
                model.raw_roi.height],
        "project": [float(x) for x in model.project3dToPixel(point)],
        "ray": list(model.projectPixelTo3dRay(uv)),
        "rectifyPoint": np.asarray(model.rectifyPoint(uv)).tolist(),
        "deltas": [model.getDeltaU(0.3, 2.0), model.getDeltaV(0.3, 2.0), model.getDeltaX(12, 2.0),
                   model.getDeltaY(12, 2.0), model.getDeltaU(0.3, 0)],
        # the undistortion maps: the same bytes; the image remapped through them differs by a
        # few levels between OpenCV versions (Debian's 4.6, minros's from PyPI)
        "maps": [hashlib.sha1(np.ascontiguousarray(m, dtype=np.float32).tobytes()).hexdigest()
                 for m in (model.mapx, model.mapy)],
        "rectified": rectified.tolist(),
    })
out["pinhole"] = cameras

stereo = []
for _ in range(6):
    model = StereoCameraModel()
    model.fromCameraInfo(camera_info(), camera_info(tx=-rnd.uniform(0.05, 0.2)))
    point = [rnd.uniform(-1, 1), rnd.uniform(-1, 1), rnd.uniform(0.5, 3)]
    stereo.append({
        "Q": model.Q.tolist(), "tfFrame": model.tfFrame(),
        "project": [[float(x) for x in uv] for uv in model.project3dToPixel(point)],
        "to3d": [float(x) for x in model.projectPixelTo3d((30.0, 20.0), rnd.uniform(1, 20))],
        "to3d_zero": [float(x) for x in model.projectPixelTo3d((30.0, 20.0), 0.0)],
        "depth": [model.getZ(7.5), model.getDisparity(1.5), model.getZ(0), model.getDisparity(0)],
    })
out["stereo"] = stereo

print(json.dumps(out))
