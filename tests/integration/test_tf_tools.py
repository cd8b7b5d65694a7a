"""tf's tools and tutorial as processes under ``minros core``: static_transform_publisher
(tf2_ros's and tf's, also through roslaunch), tf_echo, tf_monitor, view_frames, turtle_tf's
demo, and what a listener does when /clock jumps back."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import xmlrpc.client
from pathlib import Path

import pytest

from support import IN_CI, PYTHON, Proc, ros_env


def rosrun(port: int, home: Path, pkg: str, exe: str, *args: str, env_extra=None, cwd=None) -> Proc:
    return Proc([PYTHON, "-m", "minros", "run", pkg, exe, *args], ros_env(port, home, env_extra),
                cwd=cwd)


def run_once(pkg: str, exe: str, *args: str, timeout: float = 30) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = "http://localhost:1"  # these fail before they need a master
    return subprocess.run([PYTHON, "-m", "minros", "run", pkg, exe, *args], env=env,
                          capture_output=True, text=True, timeout=timeout)


def test_static_publishers_and_tf_echo(minros_core, ros_home, tmp_path):
    launch = tmp_path / "statics.launch"
    launch.write_text('<launch>\n'
                      '  <node pkg="tf2_ros" type="static_transform_publisher" name="base_to_laser"\n'
                      '        args="0.2 0 0.3 0.5 0 0 base laser"/>\n'
                      '</launch>\n')
    launched = Proc([PYTHON, "-m", "minros", "launch", str(launch)], ros_env(minros_core, ros_home))
    periodic = rosrun(minros_core, ros_home, "tf", "static_transform_publisher",
                      "1", "2", "0", "0", "0", "0", "1", "odom", "base", "50")
    echo = None
    try:
        echo = rosrun(minros_core, ros_home, "tf", "tf_echo", "odom", "laser", "5")
        out = echo.read_until("in RPY (degree)", 30)
        block = out.splitlines()[-5:]
        assert block[0].startswith("At time ")
        assert block[1:] == [
            "- Translation: [1.200, 2.000, 0.300]",
            "- Rotation: in Quaternion [0.000, 0.000, 0.247, 0.969]",
            "            in RPY (radian) [0.000, -0.000, 0.500]",
            "            in RPY (degree) [0.000, -0.000, 28.648]",
        ]
        # Ctrl-C ends it quietly with status 0
        echo.popen.send_signal(signal.SIGINT)
        assert echo.popen.wait(10) == 0
        assert "Traceback" not in echo.output()
    finally:
        for proc in (echo, periodic, launched):
            if proc is not None:
                proc.stop()


def test_tf_echo_reports_what_is_missing(minros_core, ros_home):
    echo = rosrun(minros_core, ros_home, "tf", "tf_echo", "map", "nowhere", "5")
    try:
        out = echo.read_until("The current list of frames is:", 30)
    finally:
        echo.stop()
    assert "Failure at " in out
    assert "Exception thrown:" in out and "does not exist" in out


def test_tools_report_bad_command_lines_in_one_line():
    done = run_once("tf2_ros", "static_transform_publisher", "1", "2")
    assert done.returncode == 255
    assert "Usage: static_transform_publisher x y z qx qy qz qw frame_id child_frame_id" in done.stdout
    assert done.stderr.strip().endswith("exited due to not having the right number of arguments")
    done = run_once("tf2_ros", "static_transform_publisher", "1", "2", "x", "0", "0", "0", "a", "b")
    assert done.returncode == 255
    assert done.stderr.strip() == "static_transform_publisher: z must be a number, got 'x'"
    done = run_once("tf", "tf_echo")
    assert done.returncode == 255 and done.stdout.startswith("Usage: tf_echo source_frame target_frame")
    done = run_once("tf", "static_transform_publisher", "0", "0", "0", "0", "0", "0", "a", "a", "100")
    assert done.returncode == 1 and "target_frame and source frame are the same (a, a)" in done.stderr
    for pkg, exe in (("tf2_ros", "static_transform_publisher"), ("tf", "tf_echo"),
                     ("tf", "tf_monitor"), ("tf2_tools", "view_frames.py")):
        done = run_once(pkg, exe, "--help")
        assert done.returncode == 0 and "usage" in done.stdout.lower(), (pkg, exe, done)
    for done in (run_once("tf", "tf_monitor", "a"),):
        assert done.returncode == 255 and "usage: tf_monitor framea frameb" in done.stderr
    assert all("Traceback" not in d.stderr for d in (done,))


@pytest.mark.smoke
def test_same_frame_twice_is_refused(minros_core, ros_home):
    proc = rosrun(minros_core, ros_home, "tf2_ros", "static_transform_publisher",
                  "0", "0", "0", "0", "0", "0", "a", "a")
    assert proc.popen.wait(30) == 1
    assert "target_frame and source frame are the same (a, a) this cannot work" in proc.output()


def test_tf_monitor_lists_frames_and_broadcasters(minros_core, ros_home):
    static = rosrun(minros_core, ros_home, "tf2_ros", "static_transform_publisher",
                    "0", "0", "1", "0", "0", "0", "base", "laser", "__name:=laser_static")
    periodic = rosrun(minros_core, ros_home, "tf", "static_transform_publisher",
                      "1", "0", "0", "0", "0", "0", "odom", "base", "20", "__name:=odom_caster")
    monitor = None
    try:
        static.read_until("Spinning until killed", 30)
        monitor = rosrun(minros_core, ros_home, "tf", "tf_monitor", "odom", "laser")
        out = monitor.read_until("Node: /odom_caster", 30)
    finally:
        for proc in (monitor, periodic, static):
            if proc is not None:
                proc.stop()
    assert "Waiting for transform chain to become available between odom and laser" in out
    assert "RESULTS: for odom to laser" in out
    assert "Chain is: odom -> base -> laser" in out
    assert "Frame: laser published by /laser_static(static) Average Delay: 0 Max Delay: 0" in out
    assert "Frame: base published by /odom_caster Average Delay: " in out


def test_view_frames_draws_the_tree(minros_core, ros_home, tmp_path):
    caster = rosrun(minros_core, ros_home, "tf2_ros", "static_transform_publisher",
                    "0", "0", "1", "0", "0", "0", "base", "laser", "__name:=laser_static")
    try:
        caster.read_until("Spinning until killed", 30)
        # no Graphviz on PATH: the tree as text, and frames.gv to draw later
        text_dir = tmp_path / "text"
        text_dir.mkdir()
        bare = {"PATH": str(Path(PYTHON).parent)}
        proc = rosrun(minros_core, ros_home, "tf2_tools", "view_frames.py", "--duration", "1",
                      env_extra=bare, cwd=text_dir)
        assert proc.popen.wait(60) == 0
        out = proc.output()
        assert "base\n└── laser  (/laser_static, static)" in out
        assert "Graphviz's dot is not installed" in out
        gv = (text_dir / "frames.gv").read_text()
        assert '"base" -> "laser"[label=" Broadcaster: /laser_static\\n' in gv
        assert gv.rstrip().endswith('}->"base";\n}')
        # with Graphviz: frames.pdf (and frames.png on request)
        if shutil.which("dot") is None:
            if IN_CI:
                pytest.fail("Graphviz is not installed (scripts/install-ros-reference.sh)")
            pytest.skip("Graphviz is not installed")
        proc = rosrun(minros_core, ros_home, "tf2_tools", "view_frames.py", "--duration", "1",
                      "--png", cwd=tmp_path)
        assert proc.popen.wait(60) == 0, proc.output()
        assert (tmp_path / "frames.pdf").read_bytes().startswith(b"%PDF")
        assert (tmp_path / "frames.png").read_bytes().startswith(b"\x89PNG")
    finally:
        caster.stop()


CLOCK_JUMP = r'''
import threading, time
import rospy, tf2_ros
from geometry_msgs.msg import TransformStamped
from rosgraph_msgs.msg import Clock

rospy.init_node("time_traveller")
clock_pub = rospy.Publisher("/clock", Clock, queue_size=10)
buf = tf2_ros.Buffer()
listener = tf2_ros.TransformListener(buf)
caster = tf2_ros.TransformBroadcaster()
now = [rospy.Time(100)]

def tick():  # simulated time runs on, from wherever it was set last
    while not rospy.is_shutdown():
        clock_pub.publish(Clock(clock=now[0]))
        now[0] += rospy.Duration(0, 10000000)
        time.sleep(0.01)

def send(t):
    m = TransformStamped()
    m.header.frame_id, m.child_frame_id, m.header.stamp = "world", "robot", t
    m.transform.rotation.w = 1.0
    caster.sendTransform(m)

threading.Thread(target=tick, daemon=True).start()
while rospy.get_time() < 100:
    time.sleep(0.01)
for _ in range(30):
    send(rospy.Time.now())
    time.sleep(0.01)
print("BEFORE", buf.can_transform("world", "robot", rospy.Time(100, 100000000), rospy.Duration(2)), flush=True)
now[0] = rospy.Time(50)  # /clock jumps back 50 s, as when a bag loops
while rospy.get_time() > 60:
    time.sleep(0.01)
for _ in range(30):
    send(rospy.Time.now())
    time.sleep(0.01)
try:
    buf.lookup_transform("world", "robot", rospy.Time(100, 100000000))
    print("AFTER old data still there", flush=True)
except tf2_ros.ExtrapolationException as exc:
    print("AFTER ExtrapolationException", flush=True)
start = time.monotonic()
ok = buf.can_transform("world", "robot", rospy.Time(100), rospy.Duration(1))
print("WAIT %s %.1f" % (ok, time.monotonic() - start), flush=True)
print("LATEST", buf.lookup_transform("world", "robot", rospy.Time()).header.stamp.secs, flush=True)
'''


def test_clock_jump_back_clears_the_buffer_without_crash_or_hang(minros_core, ros_home, tmp_path):
    env = ros_env(minros_core, ros_home)
    master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
    assert master.setParam("/test", "/use_sim_time", True)[0] == 1
    script = tmp_path / "jump.py"
    script.write_text(CLOCK_JUMP)
    proc = Proc([PYTHON, str(script)], env)
    try:
        out = proc.read_until("LATEST", 60)
    finally:
        proc.stop()
    assert "BEFORE True" in out
    assert "Detected jump back in time of" in out and "Clearing TF buffer." in out
    assert "AFTER ExtrapolationException" in out
    wait = next(line for line in out.splitlines() if line.startswith("WAIT"))
    assert wait.split()[1] == "False" and float(wait.split()[2]) < 5.0
    assert "LATEST 5" in out  # data of the new timeline (50.x s)
    assert "Traceback" not in out


FOLLOW_PROBE = r'''
import json, math, time
import rospy
from geometry_msgs.msg import Twist
from turtlesim.msg import Pose

rospy.init_node("follow_probe")
poses = {}
for name in ("turtle1", "turtle2"):
    rospy.Subscriber("/%s/pose" % name, Pose, lambda m, n=name: poses.__setitem__(n, m))
deadline = time.time() + 30
while len(poses) < 2 and time.time() < deadline:
    time.sleep(0.05)

def gap():
    a, b = poses["turtle1"], poses["turtle2"]
    return math.hypot(a.x - b.x, a.y - b.y)

start = gap()
drive = rospy.Publisher("/turtle1/cmd_vel", Twist, queue_size=1)
twist = Twist()
twist.linear.x = 2.0
end = time.time() + 1.0
while time.time() < end:  # turtle1 drives away
    drive.publish(twist)
    time.sleep(0.05)
moved = gap()
deadline = time.time() + 20
while gap() > 0.5 and time.time() < deadline:
    time.sleep(0.05)
print("RESULT " + json.dumps({"start": start, "moved": moved, "end": gap()}), flush=True)
'''


def test_turtle_tf_demo_turtle2_follows_turtle1(minros_core, ros_home, tmp_path):
    env = ros_env(minros_core, ros_home, {"MINROS_HEADLESS": "1"})
    launch = Proc([PYTHON, "-m", "minros", "launch", "turtle_tf", "turtle_tf_demo.launch"], env,
                  stdin=subprocess.PIPE)
    probe_script = tmp_path / "probe.py"
    probe_script.write_text(FOLLOW_PROBE)
    probe = None
    try:
        launch.read_until("process[turtle_pointer-5]: started", 30)
        probe = Proc([PYTHON, str(probe_script)], env)
        out = probe.read_until("RESULT ", 60)
    finally:
        if probe is not None:
            probe.stop()
        launch_out = launch.stop()
    result = json.loads(out.split("RESULT ", 1)[1].splitlines()[0])
    assert result["moved"] > 0.5, result  # turtle1 got away from turtle2...
    assert result["end"] <= 0.5, result   # ...and turtle2 caught up, steered through tf
    assert "Traceback" not in launch_out


BAD_CASTER = r'''
import math
import rospy
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage

def stamped(parent, child, stamp, x=0.0, w=1.0):
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id, t.header.stamp = parent, child, stamp
    t.transform.translation.x = x
    t.transform.rotation.w = w
    return t

rospy.init_node("bad_caster")
pub = rospy.Publisher("/tf", TFMessage, queue_size=100)
fixed = rospy.Time(1000)
print("casting", flush=True)
rate = rospy.Rate(50)

def cast():
    now = rospy.Time.now()
    pub.publish(TFMessage([
        stamped("world", "good", now, 1.0),
        stamped("world", "nan_frame", now, float("nan")),   # TF_NAN_INPUT
        stamped("world", "world", now),                      # TF_SELF_TRANSFORM
        stamped("world", "squashed", now, w=3.0),            # TF_DENORMALIZED_QUATERNION
        stamped("c2", "c1", now), stamped("c1", "c2", now),  # a cycle
        stamped("/world", "/slashed", now, 2.0),             # one leading '/' is stripped
        stamped("world", "repeat", fixed),                   # TF_REPEATED_DATA from the 2nd on
    ]))

try:
    while not rospy.is_shutdown():
        cast()
        rate.sleep()
except rospy.ROSInterruptException:
    pass
'''

BAD_READER = r'''
import time
import rospy, tf2_ros
rospy.init_node("bad_reader")
buf = tf2_ros.Buffer()
tf2_ros.TransformListener(buf)
buf.can_transform("world", "good", rospy.Time(), rospy.Duration(20))
time.sleep(3.0)  # about 150 messages, each with every problem
def ask(target, source):
    try:
        t = buf.lookup_transform(target, source, rospy.Time(), rospy.Duration(0.1))
        return "ok x=%g" % t.transform.translation.x
    except tf2_ros.TransformException as exc:
        return type(exc).__name__
for pair in (("world", "good"), ("world", "slashed"), ("/world", "good"), ("world", "nan_frame"),
             ("world", "squashed"), ("c1", "world"), ("world", "repeat")):
    print("ASK %s %s -> %s" % (pair[0], pair[1], ask(*pair)), flush=True)
print("DONE", flush=True)
'''


def test_a_misbehaving_broadcaster_gets_tf2s_errors_rate_limited(minros_core, ros_home, tmp_path):
    """NaN, self transforms, bad quaternions, a cycle, leading slashes and repeated stamps on
    the wire: the listener reports each problem (not 150 times), keeps the good frames,
    answers lookups with tf2's exceptions, and neither crashes nor hangs."""
    env = ros_env(minros_core, ros_home)
    caster_script, reader_script = tmp_path / "caster.py", tmp_path / "reader.py"
    caster_script.write_text(BAD_CASTER)
    reader_script.write_text(BAD_READER)
    caster = Proc([PYTHON, str(caster_script)], env)
    reader = None
    try:
        caster.read_until("casting", 30)
        reader = Proc([PYTHON, str(reader_script)], env)
        out = reader.read_until("DONE", 60)
    finally:
        if reader is not None:
            reader.stop()
        caster_out = caster.stop()
    answers = dict(line.split(" -> ") for line in out.splitlines() if line.startswith("ASK "))
    assert answers == {
        "ASK world good": "ok x=1",
        "ASK world slashed": "ok x=2",
        "ASK /world good": "InvalidArgumentException",
        "ASK world nan_frame": "LookupException",
        "ASK world squashed": "LookupException",
        "ASK c1 world": "LookupException",  # the loop guard
        "ASK world repeat": "ok x=0",
    }
    for code in ("TF_NAN_INPUT", "TF_SELF_TRANSFORM", "TF_DENORMALIZED_QUATERNION", "TF_REPEATED_DATA"):
        count = out.count(code)
        assert 1 <= count <= 2, (code, count, out)  # reported, then rate-limited
    assert 'TF_REPEATED_DATA ignoring data with redundant timestamp for frame repeat (parent world)' in out
    assert "Traceback" not in out + caster_out
