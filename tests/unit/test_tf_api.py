"""The tf1 API (tf.Transformer...) and tf2_geometry_msgs on a buffer without a node: the same
script run by minros's stand-ins and by Debian's tf/tf2_ros gives the same answers."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from support import REFERENCE_PYTHON, reference_env, require_tf_reference

# each test starts a process (see the slow marker in pyproject.toml)
pytestmark = pytest.mark.slow

SCRIPT = r'''
import json, math
import rospy
import tf
import tf2_ros
import tf2_geometry_msgs
from geometry_msgs.msg import (PointStamped, PoseStamped, QuaternionStamped, TransformStamped,

                               Vector3Stamped, WrenchStamped)

def stamped(parent, child, secs, xyz, rpy):
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id, t.header.stamp = parent, child, rospy.Time(secs)
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    q = tf.transformations.quaternion_from_euler(*rpy)
    r = t.transform.rotation
    r.x, r.y, r.z, r.w = q
    return t

out = {}
tr = tf.TransformerROS()
tr.setTransform(stamped("map", "odom", 10, (1, 2, 0), (0, 0, 0.3)), "/a")
tr.setTransform(stamped("map", "odom", 12, (3, 2, 0), (0, 0, 0.7)), "/a")
tr.setTransform(stamped("odom", "base", 10, (0.5, 0, 0.1), (0.1, 0, 1.0)), "/b")
tr.setTransform(stamped("odom", "base", 12, (0.7, 0.1, 0.1), (0.1, 0.2, 1.4)), "/b")
t11 = rospy.Time(11)
out["lookup"] = tr.lookupTransform("/map", "base", t11)
out["latest"] = tr.lookupTransform("map", "/base", rospy.Time(0))
out["lct"] = tr.getLatestCommonTime("/map", "base").to_sec()
out["exists"] = [tr.frameExists("base"), tr.frameExists("map"), tr.frameExists("nope")]
out["strings"] = sorted(tr.getFrameStrings())
out["can"] = [tr.canTransform("/map", "/base", t11), tr.canTransform("map", "base", rospy.Time(13))]
out["chain"] = tr.chain("map", t11, "base", t11, "odom")
out["full"] = tr.lookupTransformFull("base", rospy.Time(12), "base", rospy.Time(10), "map")
out["matrix"] = tr.fromTranslationRotation(*out["lookup"]).tolist()
p = PointStamped(); p.header.frame_id, p.header.stamp = "base", t11
p.point.x, p.point.y, p.point.z = 1.0, -2.0, 0.5
q = tr.transformPoint("map", p)
out["point"] = [q.point.x, q.point.y, q.point.z, q.header.frame_id, q.header.stamp.to_sec()]
v = Vector3Stamped(); v.header = p.header; v.vector.x, v.vector.y, v.vector.z = 1.0, -2.0, 0.5
w = tr.transformVector3("map", v)
out["vector"] = [w.vector.x, w.vector.y, w.vector.z]
ps = PoseStamped(); ps.header = p.header; ps.pose.position = p.point
o = tf.transformations.quaternion_from_euler(0.4, -0.2, 2.0)
ps.pose.orientation.x, ps.pose.orientation.y, ps.pose.orientation.z, ps.pose.orientation.w = o
pp = tr.transformPose("map", ps)
out["pose"] = [pp.pose.position.x, pp.pose.position.y, pp.pose.position.z, pp.pose.orientation.x,
               pp.pose.orientation.y, pp.pose.orientation.z, pp.pose.orientation.w]
qs = QuaternionStamped(); qs.header = p.header; qs.quaternion = ps.pose.orientation
qq = tr.transformQuaternion("map", qs)
out["quaternion"] = [qq.quaternion.x, qq.quaternion.y, qq.quaternion.z, qq.quaternion.w]
try:
    tr.lookupTransform("map", "nope", t11)
except tf.LookupException as exc:
    out["missing"] = [type(exc).__name__, str(exc)]
try:
    tr.lookupTransform("map", "base", rospy.Time(20))
except tf.Exception as exc:
    out["future"] = [type(exc).__name__, str(exc)]
try:
    tr.waitForTransform("map", "base", t11, rospy.Duration(1))
except tf.Exception as exc:
    out["wait"] = str(exc)

# tf2_geometry_msgs through a tf2_ros.Buffer
buf = tf2_ros.Buffer(debug=False)
buf.set_transform(stamped("map", "odom", 10, (1, 2, 0), (0, 0, 0.3)), "/a")
buf.set_transform(stamped("map", "odom", 12, (3, 2, 0), (0, 0, 0.7)), "/a")
buf.set_transform_static(stamped("odom", "laser", 0, (0.2, 0, 0.3), (0, 0.1, 2.5)), "/s")
pl = PointStamped(); pl.header.frame_id, pl.header.stamp = "laser", t11
pl.point.x, pl.point.y, pl.point.z = 1.0, 0.5, -0.25
r = buf.transform(pl, "map")
out["t_point"] = [r.point.x, r.point.y, r.point.z, r.header.frame_id, r.header.stamp.to_sec()]
vl = Vector3Stamped(); vl.header = pl.header; vl.vector = pl.point
r = buf.transform(vl, "map")
out["t_vector"] = [r.vector.x, r.vector.y, r.vector.z]
pos = PoseStamped(); pos.header = pl.header; pos.pose.position = pl.point
for rpy in ((0.4, -0.2, 2.0), (3.0, 0.1, -2.9), (0.0, 3.1, 0.0), (1.5, 1.5, 1.5)):
    oq = tf.transformations.quaternion_from_euler(*rpy)
    pos.pose.orientation.x, pos.pose.orientation.y, pos.pose.orientation.z, pos.pose.orientation.w = oq
    r = buf.transform(pos, "map")
    out.setdefault("t_pose", []).append(
        [r.pose.position.x, r.pose.position.y, r.pose.position.z, r.pose.orientation.x,
         r.pose.orientation.y, r.pose.orientation.z, r.pose.orientation.w])
wr = WrenchStamped(); wr.header = pl.header; wr.wrench.force = pl.point; wr.wrench.torque.z = 2.0
r = buf.transform(wr, "map")
out["t_wrench"] = [r.wrench.force.x, r.wrench.force.y, r.wrench.force.z, r.wrench.torque.x,
                   r.wrench.torque.y, r.wrench.torque.z]
try:
    buf.transform(pl, "nowhere")
except tf2_ros.LookupException as exc:
    out["t_missing"] = str(exc)
try:
    buf.transform(1.5, "map")
except tf2_ros.TypeException as exc:
    out["t_type"] = "TypeException"
print(json.dumps(out))
'''


def run(python: str, env=None) -> dict:
    done = subprocess.run([python, "-c", SCRIPT], capture_output=True, text=True, timeout=120, env=env)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def close(a, b) -> bool:
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(close(x, y) for x, y in zip(a, b))
    if isinstance(a, float) or isinstance(b, float):
        return abs(a - b) <= 1e-9
    return a == b


@pytest.fixture(scope="module")
def ours() -> dict:
    return run(sys.executable)


def test_tf1_api_answers(ours):
    assert ours["exists"] == [True, False, False]  # tf1: a root frame does not "exist"
    assert ours["strings"] == ["base", "odom"]
    assert ours["can"] == [True, False]
    assert ours["chain"] == ["base", "odom", "map"]
    assert ours["lct"] == 12.0
    assert ours["missing"][0] == "LookupException"
    assert ours["future"][0] == "ExtrapolationException"
    assert ours["wait"] == "cannot wait for transform without a dedicated thread that listens to incoming TF messages"
    assert ours["t_type"] == "TypeException"


def test_tf1_and_tf2_geometry_msgs_match_debian(ours):
    require_tf_reference()
    theirs = run(REFERENCE_PYTHON, reference_env({}))
    assert set(ours) == set(theirs)
    for key in theirs:
        assert close(ours[key], theirs[key]), (key, ours[key], theirs[key])
