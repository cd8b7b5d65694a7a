"""``minros sim`` as a user runs it: the launch it makes (simulator, map_server, move_base, a
master of its own), observed and driven by minros clients: topics and frames as TurtleBot3's,
the latched map and static_map, map_saver, navigation goals in several frames and the reasons
goals fail, ``move_base_simple/goal`` from rostopic, bad input, several robots, the top-down
view, simulated time. Debian's rospy against the same: tests/interop/test_sim_interop.py."""

from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path

import numpy as np
import pytest

from sim_support import READY, SEND_GOAL, WATCH, Sim, check_probe, probe
from support import PYTHON, Proc, free_port, ros_env


@pytest.fixture(scope="module")
def sim(tmp_path_factory):
    home = tmp_path_factory.mktemp("sim_home")
    (home / "log").mkdir()
    running = Sim(home)
    try:
        yield running
    finally:
        running.stop()


def test_topics_frames_and_map_are_turtlebot3s(sim):
    seen = probe(sim)
    check_probe(seen)
    # the robot starts at the origin facing +x, with 2.4 m free ahead of its laser
    assert seen["scan"]["ahead"] == pytest.approx(2.45 + 0.032, abs=1e-3)
    assert seen["laser_in_map"] == pytest.approx([-0.032, 0.0, 0.182], abs=1e-6)
    nodes = sim.tool("node", "list").stdout.split()
    assert {"/sim", "/map_server", "/move_base"} <= set(nodes)
    types = sim.tool("topic", "list", "-v").stdout
    for line in ("/cmd_vel [geometry_msgs/Twist]", "/scan [sensor_msgs/LaserScan]",
                 "/odom [nav_msgs/Odometry]", "/map [nav_msgs/OccupancyGrid]",
                 "/map_metadata [nav_msgs/MapMetaData]", "/tf [tf2_msgs/TFMessage]",
                 "/joint_states [sensor_msgs/JointState]", "/sim/view [sensor_msgs/Image]",
                 "/move_base/goal [move_base_msgs/MoveBaseActionGoal]",
                 "/move_base/NavfnROS/plan [nav_msgs/Path]"):
        assert line in types


@pytest.mark.smoke
def test_map_saver_writes_what_map_server_serves(sim, tmp_path):
    from minros.sim import mapfile
    from minros.sim.world import DEFAULT_WORLD

    result = sim.tool("run", "map_server", "map_saver", "-f", str(tmp_path / "saved"), timeout=30)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Received a 200 X 160 map @ 0.050 m/pix" in result.stdout + result.stderr
    saved, _ = mapfile.load_map(str(tmp_path / "saved.yaml"))
    original, _ = mapfile.load_map(DEFAULT_WORLD)
    assert np.array_equal(saved.data, original.data) and saved.origin == original.origin
    bad = sim.tool("run", "map_server", "map_saver", "--occ", "10", "--free", "20")
    assert bad.returncode == 1
    assert bad.stderr.strip() == "map_saver: threshold_free must be smaller than threshold_occupied"


def test_a_second_map_server_remapped_and_change_map(sim, tmp_path):
    from minros.sim import mapfile
    from minros.sim.grid import GridMap

    small = GridMap(np.array([[0, 100], [-1, 0]], np.int8), 0.5, (1.0, 2.0, 0.0))
    mapfile.save_map(small, str(tmp_path / "small"))
    server = Proc([PYTHON, "-m", "minros", "run", "map_server", "map_server",
                   str(tmp_path / "small.yaml"), "map:=/map2", "map_metadata:=/map2_metadata",
                   "static_map:=/static_map2", "change_map:=/change_map2"], sim.env)
    try:
        server.read_until("Read a 2 X 2 map @ 0.500 m/cell", timeout=20)
        names = sim.tool("node", "list").stdout.split()
        assert any(n.startswith("/map_server_") for n in names)  # anonymous, as map_server
        meta = sim.tool("topic", "echo", "-n", "1", "/map2_metadata/width").stdout
        assert meta.split()[0] == "2"
        missing = sim.tool("service", "call", "/change_map2", str(tmp_path / "nope.yaml"))
        assert "result: 1" in missing.stdout  # RESULT_MAP_DOES_NOT_EXIST
        from minros.sim.world import DEFAULT_WORLD

        changed = sim.tool("service", "call", "/change_map2", DEFAULT_WORLD)
        assert "result: 0" in changed.stdout
        width = sim.tool("topic", "echo", "-n", "1", "/map2/info/width").stdout
        assert width.split()[0] == "200"
    finally:
        out = server.stop()
    assert "Traceback" not in out


def test_navigation_goals_in_map_and_odom_frames(sim):
    sim.reset()
    result = sim.python(SEND_GOAL, "1.5", "1.0", "90", timeout=90)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Result: SUCCEEDED: Goal reached." in result.stdout
    x, y = sim.ground_truth()
    assert math.hypot(x - 1.5, y - 1.0) < 0.12
    # odom's origin is the start pose (the map's origin here): (-0.5, 0.5) in odom
    result = sim.python(SEND_GOAL, "-0.5", "0.5", "0", "odom", timeout=90)
    assert "Result: SUCCEEDED: Goal reached." in result.stdout, result.stdout + result.stderr
    x, y = sim.ground_truth()
    assert math.hypot(x + 0.5, y - 0.5) < 0.12
    # and relative to the robot itself: 0.5 m ahead of base_footprint
    result = sim.python(SEND_GOAL, "0.5", "0", "0", "base_footprint", timeout=90)
    assert "Result: SUCCEEDED" in result.stdout, result.stdout + result.stderr
    x2, y2 = sim.ground_truth()
    assert math.hypot(x2 - x, y2 - y) == pytest.approx(0.5, abs=0.12)


@pytest.mark.parametrize("args, reason", [
    (["1", "0", "0", "nowhere"], "ABORTED: Failed to transform the goal pose from nowhere into "
                                 "the map frame: \"nowhere\" passed to lookupTransform argument "
                                 "source_frame does not exist."),
    (["4.0", "-2.1"], "ABORTED: No path to the goal: the goal is in an obstacle, or closer to one "
                      "than the robot's radius"),
    (["40", "0"], "ABORTED: No path to the goal: the goal (40.00, 0.00) is outside the map"),
])
def test_goals_that_cannot_be_reached_are_aborted_with_the_reason(sim, args, reason):
    result = sim.python(SEND_GOAL, *args, timeout=60)
    assert result.returncode == 2
    assert f"Result: {reason}" in result.stdout
    assert "Traceback" not in result.stderr


def test_invalid_quaternion_is_aborted_as_move_base_does(sim):
    code = (
        "import actionlib, rospy\n"
        "from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal\n"
        "rospy.init_node('zero_q')\n"
        "c = actionlib.SimpleActionClient('move_base', MoveBaseAction)\n"
        "c.wait_for_server(rospy.Duration(20))\n"
        "g = MoveBaseGoal(); g.target_pose.header.frame_id = 'map'\n"
        "c.send_goal(g); c.wait_for_result(rospy.Duration(20))\n"
        "print(c.get_state(), c.get_goal_status_text())\n")
    result = sim.python("-c", code)
    assert result.stdout.strip() == ("4 Aborting on goal because it was sent with an invalid "
                                     "quaternion")


@pytest.mark.parametrize("position", ["float('nan'), 1.0", "1.0, float('inf')"])
def test_non_finite_goal_position_is_refused_in_one_line(sim, position):
    code = (
        "import actionlib, rospy\n"
        "from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal\n"
        "rospy.init_node('nan_goal')\n"
        "c = actionlib.SimpleActionClient('move_base', MoveBaseAction)\n"
        "c.wait_for_server(rospy.Duration(20))\n"
        "g = MoveBaseGoal(); g.target_pose.header.frame_id = 'map'\n"
        f"g.target_pose.pose.position.x, g.target_pose.pose.position.y = {position}\n"
        "g.target_pose.pose.orientation.w = 1.0\n"
        "c.send_goal(g); c.wait_for_result(rospy.Duration(20))\n"
        "print(c.get_state(), c.get_goal_status_text())\n")
    result = sim.python("-c", code)
    state, _, text = result.stdout.strip().partition(" ")
    assert state == "4", result.stdout + result.stderr
    assert text.startswith("Aborting on goal because it was sent with a non-finite position "
                           "(x="), text
    # move_base said so in one line, with no traceback
    out = sim.proc.read_until("non-finite position", timeout=10)
    assert "Traceback" not in out and "cannot convert" not in out
    assert sim.proc.alive()


def test_simple_goal_from_rostopic_pub(sim):
    sim.reset()
    result_echo = Proc([PYTHON, "-m", "minros", "topic", "echo", "-n", "1",
                        "/move_base/result/status/status"], sim.env)
    try:
        pub = sim.tool("topic", "pub", "-1", "/move_base_simple/goal", "geometry_msgs/PoseStamped",
                       "{header: {frame_id: map}, pose: {position: {x: 1.0, y: -0.6}, "
                       "orientation: {w: 1.0}}}")
        assert pub.returncode == 0, pub.stderr
        out = result_echo.read_until("---", timeout=60)
    finally:
        result_echo.stop()
    assert "3" in out.split("---")[0]  # SUCCEEDED
    x, y = sim.ground_truth()
    assert math.hypot(x - 1.0, y + 0.6) < 0.12


def test_cmd_vel_drives_and_nan_is_one_warning(sim):
    sim.reset()
    pub = Proc([PYTHON, "-m", "minros", "topic", "pub", "-r", "10", "/cmd_vel", "geometry_msgs/Twist",
                "{linear: {x: 0.5}}"], sim.env)
    try:
        watched = json.loads(sim.python(WATCH, "2.0").stdout)
    finally:
        pub.stop()
    # clamped to the Burger's 0.22 m/s: about 0.44 m in 2 s, straight along +x
    xs = [p[0] for p in watched]
    assert 0.3 < xs[-1] - xs[0] < 0.5 and all(abs(p[1]) < 1e-6 for p in watched)
    bad = sim.tool("topic", "pub", "-1", "/cmd_vel", "geometry_msgs/Twist", "{linear: {x: .nan}}")
    assert bad.returncode == 0
    out = sim.proc.read_until("non-finite", timeout=10)
    line = [x for x in out.splitlines() if "non-finite" in x][0]
    assert "/cmd_vel: non-finite velocity command (linear.x=nan, angular.z=0.0) ignored" in line
    assert sim.proc.alive()


def test_top_down_view_is_an_image_topic(sim):
    code = ("import rospy\nfrom sensor_msgs.msg import Image\nrospy.init_node('view')\n"
            "m = rospy.wait_for_message('/sim/view', Image, timeout=20)\n"
            "print(m.width, m.height, m.encoding, len(m.data), m.header.frame_id)\n")
    result = sim.python("-c", code)
    width, height, encoding, size, frame = result.stdout.split()
    assert (int(width), int(height), encoding, frame) == (600, 480, "bgr8", "map")
    assert int(size) == 600 * 480 * 3


def test_print_launch_is_the_launch_minros_sim_runs(tmp_path, ros_home):
    from minros.launch.loader import Loader

    env = ros_env(free_port(), ros_home)
    (tmp_path / "my world").mkdir()
    from minros.sim.world import DEFAULT_WORLD

    world = tmp_path / "my world" / "rooms.yaml"
    world.write_text(Path(DEFAULT_WORLD).read_text().replace("image: rooms.pgm",
                                                             f"image: {Path(DEFAULT_WORLD).parent / 'rooms.pgm'}"))
    done = subprocess.run([PYTHON, "-m", "minros", "sim", str(world), "--robots", "2", "--speed",
                           "3", "--laser-rate", "5", "--web", "9191", "--print-launch"],
                          env=env, capture_output=True, text=True, timeout=30, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    config = Loader().load_string(done.stdout, [], "<test>")
    nodes = {n.resolved_name: n for n in config.nodes}
    assert set(nodes) == {"/sim", "/map_server", "/tb3_0/move_base", "/tb3_1/move_base",
                          "/minros_web"}
    sim_args = nodes["/sim"].args
    # the world's path survives its space; both robots are placed here, by name
    assert f"'{world}'" in sim_args and "--clock" in sim_args and "--speed=3.0" in sim_args
    assert "--laser-rate=5.0" in sim_args
    assert "--robot=tb3_0=0.0,0.0,0.0" in sim_args and "--robot=tb3_1=0.0,0.5,0.0" in sim_args
    assert nodes["/sim"].required
    assert config.params["/use_sim_time"] is True
    assert config.params["/tb3_1/move_base/global_costmap/robot_base_frame"] == "tb3_1/base_footprint"
    assert ("map", "/map") in nodes["/tb3_0/move_base"].remap_args
    assert config.params["/minros_web/port"] == 9191
    help_text = subprocess.run([PYTHON, "-m", "minros", "sim", "--help"], env=env,
                               capture_output=True, text=True, timeout=30).stdout
    assert "--no-nav" in help_text and "--robots N" in help_text


def test_bad_world_files_are_one_line(tmp_path, ros_home):
    env = ros_env(free_port(), ros_home)
    missing = subprocess.run([PYTHON, "-m", "minros", "sim", str(tmp_path / "nope.yaml")],
                             env=env, capture_output=True, text=True, timeout=30)
    assert missing.returncode == 1
    assert missing.stderr.strip() == (f"minros sim: map file {tmp_path / 'nope.yaml'} does not exist "
                                      "(give the path of a map .yaml, as map_saver writes them)")
    (tmp_path / "garbled.pgm").write_bytes(b"P5\n10 10\n255\n\x00\x01")
    (tmp_path / "garbled.yaml").write_text("image: garbled.pgm\nresolution: 0.05\n"
                                           "origin: [0, 0, 0]\nnegate: 0\n"
                                           "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    for argv in ([PYTHON, "-m", "minros", "sim", str(tmp_path / "garbled.yaml")],
                 [PYTHON, "-m", "minros", "run", "map_server", "map_server",
                  str(tmp_path / "garbled.yaml")]):
        result = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=30)
        assert result.returncode == 1
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and "garbled.pgm" in lines[0] and "Traceback" not in result.stderr
    result = subprocess.run([PYTHON, "-m", "minros", "sim", "--robot", "4.0,-2.1,0"], env=env,
                            capture_output=True, text=True, timeout=30)
    assert result.returncode == 1
    assert "cannot start at (4.00, -2.10)" in result.stderr


# two simulated robots and their move_base nodes drive in real time: CPU time the test cannot
# get (beside other workers) makes them miss their goals' time bound
@pytest.mark.timing
def test_two_robots_are_namespaced_and_navigate_at_once(tmp_path_factory):
    home = tmp_path_factory.mktemp("sim2_home")
    (home / "log").mkdir()
    sim = Sim(home, "--robots", "2", wait_for=("Hz steps", READY, READY))
    try:
        check_probe(probe(sim, "tb3_1"), "tb3_1/")
        goals = [Proc([PYTHON, SEND_GOAL, "2.0", "0.5"], dict(sim.env, ROS_NAMESPACE="tb3_0")),
                 Proc([PYTHON, SEND_GOAL, "2.0", "0.0"], dict(sim.env, ROS_NAMESPACE="tb3_1"))]
        outs = [g.read_until("Result:", timeout=120) for g in goals]
        for g in goals:
            g.stop()
        assert all("Result: SUCCEEDED" in out for out in outs), outs
        assert math.hypot(*np.subtract(sim.ground_truth("tb3_0"), (2.0, 0.5))) < 0.12
        assert math.hypot(*np.subtract(sim.ground_truth("tb3_1"), (2.0, 0.0))) < 0.12
    finally:
        out = sim.stop()
    assert "Bump!" not in out and "Traceback" not in out


def test_a_robot_stuck_by_a_wall_recovers_then_aborts_with_the_reason(tmp_path_factory):
    """5 cm from the west wall, the follower finds no valid command (the wall is in its safety
    corridor). It used to replan "plan of 0.6 m" every second, ACTIVE forever; move_base's
    executive runs its recovery behaviours, then aborts saying why."""
    home = tmp_path_factory.mktemp("sim_stuck_home")
    (home / "log").mkdir()
    sim = Sim(home, "--no-nav", "--robot=-4.75,0,1.5708", wait_for=("Hz steps",))
    nav = Proc([PYTHON, "-m", "minros", "run", "move_base", "move_base", "map:=/map",
                "_controller_patience:=3.0", "_oscillation_timeout:=0"], sim.env)
    try:
        nav.read_until(READY, timeout=30)
        code = (
            "import actionlib, rospy, time\n"
            "from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal\n"
            "rospy.init_node('stuck_goal')\n"
            "c = actionlib.SimpleActionClient('move_base', MoveBaseAction)\n"
            "c.wait_for_server(rospy.Duration(20))\n"
            "g = MoveBaseGoal(); g.target_pose.header.frame_id = 'map'\n"
            "g.target_pose.pose.position.x, g.target_pose.pose.position.y = -4.7, 0.6\n"
            "g.target_pose.pose.orientation.z = g.target_pose.pose.orientation.w = 0.5 ** 0.5\n"
            "start = time.monotonic()\n"
            "c.send_goal(g); c.wait_for_result(rospy.Duration(60))\n"
            "print(c.get_state(), round(time.monotonic() - start), c.get_goal_status_text())\n")
        result = sim.python("-c", code, timeout=90)
        state, seconds, text = result.stdout.strip().split(" ", 2)
        assert state == "4", result.stdout + result.stderr  # ABORTED, not 1 (ACTIVE)
        assert text.startswith("Failed to find a valid control. Even after executing recovery "
                               "behaviors. (no valid velocity command for "), text
        assert "is in its way)" in text
        # 3 s of patience, two turns of 2 pi at 1 rad/s: well within the minute
        assert int(seconds) < 40
    finally:
        log = nav.stop()
        sim.stop()
    tried = [line.rsplit(": ", 1)[-1] for line in log.splitlines() if "; recovery " in line]
    assert tried == ["conservative_reset", "rotate_recovery", "aggressive_reset",
                     "rotate_recovery"], log
    # a first plan, one a second while blocked within the patience, one after each recovery
    assert log.count("plan of") <= 10 and "Traceback" not in log


def test_simulated_time_as_fast_as_possible(tmp_path_factory):
    home = tmp_path_factory.mktemp("sim3_home")
    (home / "log").mkdir()
    sim = Sim(home, "--no-nav", "--no-map-server", "--speed", "0", wait_for=("Hz steps",))
    try:
        assert sim.tool("param", "get", "/use_sim_time").stdout.strip() == "true"
        code = ("import rospy\nfrom nav_msgs.msg import Odometry\nrospy.init_node('t')\n"
                "m = rospy.wait_for_message('/odom', Odometry, timeout=20)\n"
                "n = rospy.Time.now()\nprint(m.header.stamp.to_sec(), n.to_sec())\n")
        stamp, now = (float(v) for v in sim.python("-c", code).stdout.split())
        # simulated seconds since the start, not the epoch; the client's clock follows /clock
        assert 0 < stamp < 1e6 and 0 < now < 1e6
    finally:
        sim.stop()
