"""``minros sim`` with Debian's ROS 1 as the client: the classic rospy tutorials run against it
unmodified under /usr/bin/python3 (Debian's rospy, actionlib, tf2_ros, move_base_msgs), side
by side with the same scripts under minros; and minros sim on Debian's rosmaster."""

from __future__ import annotations

import json
import math
import signal

import pytest

from sim_support import SEND_GOAL, WATCH, Sim, check_probe, probe
from support import EXAMPLES, PYTHON, REFERENCE_PYTHON, Proc, reference_env, require_reference

pytestmark = pytest.mark.interop
AVOID = str(EXAMPLES / "sim" / "avoid_obstacles.py")


def home_for(factory, name):
    home = factory.mktemp(name)
    (home / "log").mkdir()
    return home


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    require_reference()
    running = Sim(home_for(tmp_path_factory, "sim_interop"))
    try:
        yield running
    finally:
        running.stop()


def test_debian_rospy_and_tf2_see_what_minros_sees(sim):
    debian = probe(sim, python=REFERENCE_PYTHON, env=reference_env(sim.env))
    check_probe(debian)
    ours = probe(sim, python=PYTHON)
    assert debian == ours


def test_send_a_navigation_goal_under_debians_rospy(sim):
    sim.reset()
    result = sim.debian(SEND_GOAL, "1.5", "-0.5", "180", timeout=90)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Result: SUCCEEDED: Goal reached." in result.stdout
    x, y = sim.ground_truth()
    assert math.hypot(x - 1.5, y + 0.5) < 0.12
    # a goal in odom, and one that fails, from Debian's client too
    result = sim.debian(SEND_GOAL, "0.3", "0.3", "0", "odom", timeout=90)
    assert "Result: SUCCEEDED: Goal reached." in result.stdout, result.stdout + result.stderr
    result = sim.debian(SEND_GOAL, "1", "0", "0", "nowhere", timeout=60)
    assert result.returncode == 2
    assert ("Result: ABORTED: Failed to transform the goal pose from nowhere into the map frame"
            in result.stdout)


@pytest.mark.parametrize("client", ["minros", "debian"])
def test_obstacle_avoidance_tutorial_wanders_without_a_bump(tmp_path_factory, client):
    require_reference()
    sim = Sim(home_for(tmp_path_factory, f"avoid_{client}"), "--no-nav", wait_for=("Hz steps",))
    try:
        if client == "debian":
            avoider = Proc([REFERENCE_PYTHON, AVOID], reference_env(sim.env))
        else:
            avoider = Proc([PYTHON, AVOID], sim.env)
        try:
            watched = sim.python(WATCH, "25", timeout=60)
        finally:
            avoider.popen.send_signal(signal.SIGINT)
            avoider_out = avoider.stop()
    finally:
        out = sim.stop()
    poses = json.loads(watched.stdout)
    travelled = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(poses, poses[1:]))
    assert travelled > 2.5, (travelled, avoider_out)
    assert "Bump!" not in out
    assert "Traceback" not in avoider_out


def test_minros_sim_on_debians_rosmaster(debian_rosmaster, tmp_path_factory):
    sim = Sim(home_for(tmp_path_factory, "sim_rosmaster"), port=debian_rosmaster)
    try:
        assert "auto-starting new master" not in sim.startup
        listing = sim.run(["/usr/bin/rostopic", "list"], env=reference_env(sim.env)).stdout.split()
        assert {"/scan", "/odom", "/cmd_vel", "/map", "/move_base/goal"} <= set(listing)
        result = sim.debian(SEND_GOAL, "1.0", "0.5", timeout=90)
        assert "Result: SUCCEEDED: Goal reached." in result.stdout, result.stdout + result.stderr
    finally:
        sim.stop()
