#!/usr/bin/env python3
"""PyKDL benchmark: minros's pure-Python PyKDL beside Debian's C++ python3-pykdl (pybind11).

    .venv/bin/python benchmarks/kdl.py [--rounds 3] [--seconds 0.3] [--points 100000]

The calls robot loops make (Vector arithmetic, Frame * Vector, Frame * Frame, inversions,
quaternion and RPY conversions, element access), the chain solvers on a 7-joint arm (forward
kinematics, Jacobian, pseudo-inverse velocity IK, Newton-Raphson position IK), and the libraries
over them: tf2_sensor_msgs' do_transform_cloud on ``--points`` points and laser_geometry's
projectLaser on a 1440-range scan. The same setup text runs here on minros and under
/usr/bin/python3 on Debian's packages (minros.kdl.testing's oracle); each figure is the best
batch's rate (minros.msgs.testing.best_rate), contenders alternating round by round, median of
the rounds. "minros speed" above 1 means minros is faster.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from typing import Dict, List

from _bytecode import byte_compile_minros  # benchmarks/ is the script's directory: on sys.path

SETUP = """
import math
v = K.Vector(1.0, 2.0, 3.0); w = K.Vector(0.5, -1.0, 2.0)
R = K.Rotation.RPY(0.1, 0.2, 0.3); F = K.Frame(R, v); G = K.Frame(K.Rotation.RPY(0.3, 0.2, 0.1), w)
C = K.Chain()
for i in range(7):
    axis = K.Vector(0.0, 0.0, 1.0) if i % 2 == 0 else K.Vector(0.0, 1.0, 0.0)
    C.addSegment(K.Segment("l%d" % i, K.Joint("j%d" % i, K.Vector(0.0, 0.0, 0.0), axis, K.Joint.RotAxis),
                           K.Frame(K.Rotation.RPY(0.1 * i, 0.0, 0.2), K.Vector(0.0, 0.05, 0.3))))
fk = K.ChainFkSolverPos_recursive(C); jsol = K.ChainJntToJacSolver(C); vik = K.ChainIkSolverVel_pinv(C)
ik = K.ChainIkSolverPos_NR(C, fk, vik)
q = K.JntArray(7); qi = K.JntArray(7); qo = K.JntArray(7)
for i in range(7):
    q[i] = 0.3 * (i + 1); qi[i] = 0.3 * (i + 1) + 0.1
out = K.Frame(); jac = K.Jacobian(7); target = K.Frame(); fk.JntToCart(q, target)
twist = K.Twist(K.Vector(0.1, 0.0, -0.1), K.Vector(0.0, 0.2, 0.1))
"""

LIBRARIES = """
import numpy as np
import rospy
import tf2_sensor_msgs
from geometry_msgs.msg import TransformStamped
from laser_geometry import LaserProjection
from sensor_msgs import point_cloud2
from sensor_msgs.msg import LaserScan, PointField
from std_msgs.msg import Header
rng = np.random.default_rng(1)
fields = [PointField(c, 4 * i, PointField.FLOAT32, 1) for i, c in enumerate("xyz")]
fields.append(PointField("intensity", 12, PointField.FLOAT32, 1))
cloud = point_cloud2.create_cloud(Header(frame_id="lidar"), fields, rng.normal(size=(POINTS, 4)).astype(np.float32).tolist())
t = TransformStamped(); t.header.frame_id = "map"
t.transform.translation.x = 1.0; t.transform.rotation.z = math.sin(0.3); t.transform.rotation.w = math.cos(0.3)
scan = LaserScan(); scan.angle_min = -math.pi; scan.angle_increment = 2 * math.pi / 1440
scan.angle_max = scan.angle_min + 1439 * scan.angle_increment; scan.range_min = 0.1; scan.range_max = 30.0
scan.ranges = rng.uniform(0.0, 35.0, 1440).astype(np.float32).tolist()
scan.intensities = rng.uniform(0.0, 100.0, 1440).astype(np.float32).tolist()
projection = LaserProjection()
"""

STATEMENTS = {
    "Vector(x, y, z)": "K.Vector(1.0, 2.0, 3.0)",
    "Vector + Vector": "v + w",
    "Vector * 2.0": "v * 2.0",
    "Vector * Vector (cross)": "v * w",
    "Rotation * Vector": "R * v",
    "Frame * Vector": "F * v",
    "Frame * Frame": "F * G",
    "Frame.Inverse()": "F.Inverse()",
    "Rotation.Quaternion(...)": "K.Rotation.Quaternion(0.1, 0.2, 0.3, 0.9)",
    "Rotation.RPY(...)": "K.Rotation.RPY(0.1, 0.2, 0.3)",
    "Rotation.GetQuaternion()": "R.GetQuaternion()",
    "Rotation.GetRPY()": "R.GetRPY()",
    "frame.p[2] (read)": "F.p[2]",
    "vector[0] (read)": "v[0]",
    "diff(Frame, Frame)": "K.diff(F, G)",
    "FK, 7-joint arm": "fk.JntToCart(q, out)",
    "Jacobian, 7-joint arm": "jsol.JntToJac(q, jac)",
    "pinv velocity IK, 7 joints": "vik.CartToJnt(q, twist, qo)",
    "NR position IK, 7 joints": "ik.CartToJnt(qi, target, qo)",
    "do_transform_cloud": "tf2_sensor_msgs.do_transform_cloud(cloud, t)",
    "projectLaser, 1440 ranges": "projection.projectLaser(scan)",
}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=0.3, help="per statement and round")
    parser.add_argument("--points", type=int, default=100000, help="points of the cloud")
    args = parser.parse_args()
    byte_compile_minros()
    import os

    from minros import kdl
    from minros.kdl.testing import KdlOracle
    from minros.msgs.testing import best_rate

    setup = SETUP + LIBRARIES.replace("POINTS", str(args.points))
    scope: Dict[str, object] = {"K": kdl}
    exec(setup, scope)  # noqa: S102 (our own text)
    calls = {name: eval("lambda: " + stmt, scope) for name, stmt in STATEMENTS.items()}  # noqa: S307
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    oracle = KdlOracle(env=env, timeout=600)
    ours: Dict[str, List[float]] = {name: [] for name in STATEMENTS}
    theirs: Dict[str, List[float]] = {name: [] for name in STATEMENTS}
    try:
        for _ in range(args.rounds):
            for name, call in calls.items():
                ours[name].append(best_rate(call, args.seconds))
            for name, rate in oracle.bench(setup, STATEMENTS, args.seconds).items():
                theirs[name].append(rate)
    finally:
        oracle.close()
    print(f"PyKDL and the libraries over it, median of {args.rounds} rounds "
          f"(cloud: {args.points} points)")
    print(f"{'operation':<30}{'minros':>12}{'Debian':>12}{'minros speed':>14}")
    for name in STATEMENTS:
        a, b = statistics.median(ours[name]), statistics.median(theirs[name])
        print(f"{name:<30}{_time(1 / a):>12}{_time(1 / b):>12}{a / b:>13.2f}x")
    return 0


def _time(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:.2f} us"
    return f"{seconds * 1e3:.2f} ms"


if __name__ == "__main__":
    sys.exit(main())
