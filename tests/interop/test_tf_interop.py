"""tf with Debian's tf2_py/tf2_ros/tf on the other side.

* the BufferCore: the same scripts of inserts and requests on minros's and on Debian's C++
  core (driven in-process under /usr/bin/python3, no master): equal results within 1e-9,
  exceptions of the same class with the same text (hypothesis, random trees);
* on the wire: Debian's tf2_ros/tf listeners read minros's broadcasters and the reverse;
* Debian's C++ tf_echo reads minros's static_transform_publisher.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from minros.tf.core import BufferCore
from minros.tf.testing import play
from support import (
    IN_CI,
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    reference_env,
    require_tf_reference,
    ros_env,
)
from tf import transformations as T

pytestmark = pytest.mark.interop


def assert_same(ours, theirs, actions):
    assert len(ours) == len(theirs)
    for action, a, b in zip(actions, ours, theirs):
        if "exc" in b:
            assert a == b, f"{action}: minros {a} vs Debian {b}"
            continue
        assert "ok" in a, f"{action}: minros raised {a}, Debian returned {b}"
        if action[0] in ("lookup", "full"):
            (stamp_a, frame_a, child_a, values_a), (stamp_b, frame_b, child_b, values_b) = a["ok"], b["ok"]
            assert (stamp_a, frame_a, child_a) == (stamp_b, frame_b, child_b), action
            assert all(abs(x - y) <= 1e-9 for x, y in zip(values_a, values_b)), (action, values_a, values_b)
        else:
            assert a == b, f"{action}: minros {a} vs Debian {b}"


# --------------------------------------------------------------------------- random trees

def unit_quaternion(raw):
    n = math.sqrt(sum(c * c for c in raw))
    return [c / n for c in raw]


@st.composite
def scenarios(draw):
    """A forest of frames with static and moving links, some bad inserts, then requests."""
    n = draw(st.integers(2, 7))
    names = [f"f{i}" for i in range(n)]
    coord = st.floats(-5, 5, allow_nan=False)
    # Shoemake's uniform rotations from three numbers in [0, 1)
    quat = st.tuples(*[st.floats(0, 1, exclude_max=True)] * 3).map(T.random_quaternion)
    stamp = st.tuples(st.integers(10, 13), st.integers(0, 999_999_999))
    actions, stamps = [], []
    for i in range(1, n):
        if draw(st.integers(0, 3)) == 0:
            continue  # a root of its own: another tree
        parent = names[draw(st.integers(0, i - 1))]
        if draw(st.integers(0, 2)) == 0:
            actions.append(["set", parent, names[i], [0, 0], [draw(coord) for _ in range(3)],
                            list(draw(quat)), "/static_caster", True])
            continue
        for t in sorted(set(draw(st.lists(stamp, min_size=1, max_size=4)))):
            stamps.append(list(t))
            # now and then a sample from another parent: no interpolation across the change
            p = names[draw(st.integers(0, n - 1))] if draw(st.integers(0, 9)) == 0 else parent
            actions.append(["set", p, names[i], list(t), [draw(coord) for _ in range(3)],
                            list(draw(quat)), "/caster", False])
    bad = draw(st.sampled_from(["none", "nan", "self", "denormalized", "repeated", "old", "slash"]))
    if bad != "none":
        child = draw(st.sampled_from(names[1:]))
        xyz, q, t = [1.0, 2.0, 3.0], [0.0, 0.0, 0.0, 1.0], [12, 0]
        parent = names[0]
        if bad == "nan":
            xyz = [float("nan"), 0.0, 0.0]
        elif bad == "self":
            parent = child
        elif bad == "denormalized":
            q = [0.0, 0.0, 0.0, 1.5]
        elif bad == "repeated" and stamps:
            t = stamps[0]
        elif bad == "old":
            t = [0, 5]
        elif bad == "slash":
            parent, child = "/" + parent, "/" + child
        actions.append(["set", parent, child, t, xyz, q, "/bad", False])
    times = stamps + [[0, 0], [9, 0], [14, 0], [11, 500_000_000], [12, 250_000_000]]
    known = st.sampled_from(names)
    frame = st.one_of(known, known, known, st.sampled_from(["nope", "/f0", ""]))
    when = st.sampled_from(times) | stamp.map(list)
    for _ in range(draw(st.integers(3, 12))):
        kind = draw(st.sampled_from(["lookup", "lookup", "can", "full", "lct"]))
        if kind == "full":
            actions.append(["full", draw(frame), draw(when), draw(frame), draw(when),
                            draw(st.sampled_from(names))])
        elif kind == "lct":
            actions.append(["lct", draw(frame), draw(frame)])
        else:
            actions.append([kind, draw(frame), draw(frame), draw(when)])
    if draw(st.booleans()):
        actions.append(["clear"])
        actions.append(["lookup", draw(frame), draw(frame), draw(when)])
    actions += [["yaml"], ["string"]]
    return actions


@settings(max_examples=500, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                    HealthCheck.too_slow])
@given(actions=scenarios())
def test_buffer_core_matches_debian_on_random_trees(tf_oracle, actions):
    ours = play(BufferCore(log=lambda level, text: None), actions)
    assert_same(ours, tf_oracle.play(actions), actions)


def test_each_exception_class_at_the_same_requests(tf_oracle):
    q = unit_quaternion([0.1, 0.2, 0.3, 0.9])
    actions = [
        ["set", "world", "a", [10, 0], [1, 2, 3], q, "/me", False],
        ["set", "world", "a", [11, 0], [2, 2, 3], unit_quaternion([0.3, 0.2, -0.3, 0.9]), "/me", False],
        ["set", "a", "b", [10, 500_000_000], [0, 1, 0], unit_quaternion([0, 0, 0.5, 0.8]), "/me", False],
        ["set", "a", "b", [11, 500_000_000], [0, 2, 0], unit_quaternion([0, 0.5, 0.5, 0.8]), "/me", False],
        ["set", "world", "s", [0, 0], [5, 0, 0], unit_quaternion([0, 0, 1, 1]), "/st", True],
        ["set", "x", "y", [10, 0], [5, 0, 0], unit_quaternion([0, 0, 1, 1]), "/st", False],
        ["set", "c1", "c2", [10, 0], [0, 0, 0], [0, 0, 0, 1], "/loop", False],
        ["set", "c2", "c1", [10, 0], [0, 0, 0], [0, 0, 0, 1], "/loop", False],
        ["lookup", "world", "b", [0, 0]],               # latest common time
        ["lookup", "b", "world", [10, 700_000_000]],    # interpolated, inverted
        ["lookup", "s", "b", [11, 0]],                  # through a static frame
        ["lookup", "world", "b", [12, 0]],              # ExtrapolationException, future
        ["lookup", "world", "b", [9, 0]],               # ExtrapolationException, past
        ["lookup", "y", "x", [11, 0]],                  # ExtrapolationException, single sample
        ["lookup", "world", "y", [0, 0]],               # ConnectivityException
        ["lookup", "nope", "b", [0, 0]],                # LookupException
        ["lookup", "/world", "b", [0, 0]],              # InvalidArgumentException
        ["lookup", "", "b", [0, 0]],                    # InvalidArgumentException
        ["lookup", "c1", "world", [10, 0]],             # a loop: LookupException
        ["lookup", "world", "c1", [0, 0]],
        ["can", "world", "c1", [10, 0]],
        ["can", "nope", "nope2", [0, 0]],
        ["lct", "b", "y"],                              # TransformException (base class)
        ["full", "s", [0, 0], "b", [11, 0], "world"],
        ["full", "b", [11, 0], "b", [11, 100], "world"],
        ["full", "b", [11, 0], "b", [11, 0], "nope"],
        ["yaml"], ["string"],
    ]
    ours = play(BufferCore(log=lambda level, text: None), actions)
    theirs = tf_oracle.play(actions)
    assert_same(ours, theirs, actions)
    classes = {r.get("exc") for r in theirs}
    assert {"ExtrapolationException", "ConnectivityException", "LookupException",
            "InvalidArgumentException", "TransformException"} <= classes


# --------------------------------------------------------------------------- on the wire

CASTER = r'''
import sys
import rospy
import tf
import tf2_ros
from geometry_msgs.msg import TransformStamped

def stamped(parent, child, xyz, q, stamp):
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id, t.header.stamp = parent, child, stamp
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    r = t.transform.rotation
    r.x, r.y, r.z, r.w = q
    return t

rospy.init_node("tf_caster")
static = tf2_ros.StaticTransformBroadcaster()
now = rospy.Time.now()
laser = stamped("base", "laser", (0.2, 0.0, 0.3), tf.transformations.quaternion_from_euler(0, 0, 0.5), now)
camera = stamped("base", "camera", (0.1, 0.05, 0.4), (0.0, 0.0, 0.0, 1.0), now)
if sys.argv[1] == "separate":  # each static frame in its own call
    static.sendTransform(laser)
    static.sendTransform(camera)
else:
    static.sendTransform([laser, camera])
caster = tf2_ros.TransformBroadcaster()
caster1 = tf.TransformBroadcaster()
print("broadcasting", flush=True)
rate = rospy.Rate(50)
while not rospy.is_shutdown():
    now = rospy.Time.now()
    caster.sendTransform(stamped("odom", "base", (1.0, 2.0, 0.0), tf.transformations.quaternion_from_euler(0, 0, 0.3), now))
    caster1.sendTransform((3.0, 0.0, 0.0), tf.transformations.quaternion_from_euler(0.1, 0, 1.0), now, "tf1_child", "base")
    rate.sleep()
'''

READER = r'''
import json
import yaml
import rospy
import tf
import tf2_ros
import tf2_geometry_msgs
from geometry_msgs.msg import PointStamped

rospy.init_node("tf_reader")
buf = tf2_ros.Buffer()
listener = tf2_ros.TransformListener(buf)
tl = tf.TransformListener()
out = {}
ok = buf.can_transform("odom", "laser", rospy.Time(), rospy.Duration(20))
out["can"] = bool(ok)
ok = buf.can_transform("odom", "camera", rospy.Time(), rospy.Duration(20))
out["can_camera"] = bool(ok)
t = buf.lookup_transform("odom", "laser", rospy.Time(0))
tr, r = t.transform.translation, t.transform.rotation
out["laser"] = [tr.x, tr.y, tr.z, r.x, r.y, r.z, r.w]
t = buf.lookup_transform("base", "camera", rospy.Time(0))
out["camera"] = [t.transform.translation.x, t.transform.translation.y, t.transform.translation.z]
p = PointStamped()
p.header.frame_id, p.header.stamp = "laser", rospy.Time(0)
p.point.x = 1.0
q = buf.transform(p, "odom", rospy.Duration(5))
out["point"] = [q.point.x, q.point.y, q.point.z, q.header.frame_id]
tl.waitForTransform("/odom", "/tf1_child", rospy.Time(), rospy.Duration(20))
trans, rot = tl.lookupTransform("/odom", "tf1_child", rospy.Time(0))
out["tf1"] = list(trans) + list(rot)
frames = yaml.safe_load(buf.all_frames_as_yaml())
out["authority"] = [frames["base"]["broadcaster"], frames["laser"]["broadcaster"],
                    frames["tf1_child"]["broadcaster"]]
try:
    buf.lookup_transform("odom", "nowhere", rospy.Time(0), rospy.Duration(0.2))
except tf2_ros.LookupException as exc:
    out["missing"] = type(exc).__name__
print("RESULT " + json.dumps(out), flush=True)
'''


def expected_tree():
    """Poses of the CASTER script's frames, composed with 4x4 matrices."""
    def pose(xyz, q):
        return T.concatenate_matrices(T.translation_matrix(xyz), T.quaternion_matrix(q))

    odom_base = pose((1.0, 2.0, 0.0), T.quaternion_from_euler(0, 0, 0.3))
    base_laser = pose((0.2, 0.0, 0.3), T.quaternion_from_euler(0, 0, 0.5))
    base_child = pose((3.0, 0.0, 0.0), T.quaternion_from_euler(0.1, 0, 1.0))
    return odom_base @ base_laser, odom_base @ base_child


def _start(impl: str, script: Path, args, port: int, home: Path) -> Proc:
    env = ros_env(port, home)
    if impl == "rospy":
        return Proc([REFERENCE_PYTHON, str(script), *args], reference_env(env))
    return Proc([PYTHON, str(script), *args], env)


def _read(caster_impl, reader_impl, tmp_path, port, home, mode="together"):
    caster_script, reader_script = tmp_path / "caster.py", tmp_path / "reader.py"
    caster_script.write_text(CASTER)
    reader_script.write_text(READER)
    caster = _start(caster_impl, caster_script, [mode], port, home)
    reader = None
    try:
        caster.read_until("broadcasting", 30)
        reader = _start(reader_impl, reader_script, [], port, home)
        out = reader.read_until("RESULT ", 60)
    finally:
        if reader is not None:
            reader.stop()
        caster.stop()
    return json.loads(out.split("RESULT ", 1)[1].splitlines()[0])


@pytest.mark.parametrize("caster_impl, reader_impl", [("minros", "rospy"), ("rospy", "minros")])
def test_listeners_read_the_other_sides_broadcasters(tmp_path, debian_rosmaster, ros_home,
                                                     caster_impl, reader_impl):
    require_tf_reference()
    got = _read(caster_impl, reader_impl, tmp_path, debian_rosmaster, ros_home)
    odom_laser, odom_child = expected_tree()
    assert got["can"] and got["can_camera"]
    assert got["laser"][:3] == pytest.approx(list(odom_laser[:3, 3]), abs=1e-9)
    q = T.quaternion_from_matrix(odom_laser)
    assert got["laser"][3:] == pytest.approx(list(q), abs=1e-9) or \
        got["laser"][3:] == pytest.approx(list(-q), abs=1e-9)
    assert got["camera"] == pytest.approx([0.1, 0.05, 0.4])
    point = odom_laser @ [1.0, 0, 0, 1]
    assert got["point"][:3] == pytest.approx(list(point[:3]), abs=1e-9) and got["point"][3] == "odom"
    assert got["tf1"][:3] == pytest.approx(list(odom_child[:3, 3]), abs=1e-9)
    # the authority is the publishing node, from the connection header
    assert got["authority"] == ["/tf_caster", "/tf_caster", "/tf_caster"]
    assert got["missing"] == "LookupException"


def test_static_frames_sent_in_separate_calls_all_reach_a_late_debian_listener(
        tmp_path, debian_rosmaster, ros_home):
    """/tf_static is latched: minros's StaticTransformBroadcaster resends every static frame of
    the node, so a listener that starts later still gets the first one."""
    require_tf_reference()
    got = _read("minros", "rospy", tmp_path, debian_rosmaster, ros_home, mode="separate")
    assert got["can"] and got["can_camera"]


def test_debians_tf_echo_reads_minros_static_transform_publisher(debian_rosmaster, ros_home):
    require_tf_reference()
    echo = "/usr/lib/tf/tf_echo"
    if not shutil.which(echo):
        if IN_CI:
            pytest.fail("tf-tools is not installed (scripts/install-ros-reference.sh)")
        pytest.skip("Debian's tf-tools is not installed")
    env = ros_env(debian_rosmaster, ros_home)
    publisher = Proc([PYTHON, "-m", "minros", "run", "tf2_ros", "static_transform_publisher",
                      "1", "2", "3", "0.5", "0.25", "-0.1", "base", "laser"], env)
    theirs = ours = None
    try:
        publisher.read_until("Spinning until killed publishing base to laser", 30)
        theirs = Proc([echo, "base", "laser"], reference_env(env))
        out_theirs = theirs.read_until("in RPY (degree)", 30)
        ours = Proc([PYTHON, "-m", "minros", "run", "tf", "tf_echo", "base", "laser"], env)
        out_ours = ours.read_until("in RPY (degree)", 30)
    finally:
        for proc in (theirs, ours, publisher):
            if proc is not None:
                proc.stop()

    def block(text):
        lines = text.splitlines()
        start = max(i for i, line in enumerate(lines) if line.startswith("At time"))
        return lines[start + 1:start + 5]

    assert block(out_ours) == block(out_theirs)
    assert block(out_ours)[0] == "- Translation: [1.000, 2.000, 3.000]"
    assert block(out_ours)[2] == "            in RPY (radian) [-0.100, 0.250, 0.500]"
