"""turtlesim simulation numerics (minros.nodes.turtlesim.sim), checked against closed forms of noetic's
Turtle::update, without ROS."""

from __future__ import annotations

import math

import numpy as np
import pytest

from minros.nodes.turtlesim import sim
from minros.nodes.turtlesim.draw_square import FORWARD, STOP_FORWARD, STOP_TURN, TURN, SquareDriver
from minros.nodes.turtlesim.mimic import twist_for_pose
from minros.nodes.turtlesim.turtle_teleop_key import BANNER, key_loop, key_to_motion


class Clock:
    """A wall clock the test moves by hand (the cmd_vel timeout uses wall time)."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def make_world():
    clock = Clock()
    logs = {"info": [], "warn": [], "error": []}
    world = sim.TurtleFrame(clock=clock, info=logs["info"].append, warn=logs["warn"].append,
                            error=logs["error"].append)
    world.tick()  # the first timer tick only records the time
    return world, clock, logs


def run(world, clock, ticks: int):
    """``ticks`` timer ticks, the wall clock advancing 16 ms each (like the real QTimer)."""
    updates = []
    for _ in range(ticks):
        clock.now += sim.DT
        updates, _ = world.tick()
    return {u.name: u for u in updates}


def test_constants_match_noetic():
    assert sim.CANVAS_METERS == pytest.approx(499 / 45, abs=1e-6)
    assert sim.CANVAS_METERS == float(np.float32(499 / 45))
    assert f"{sim.CENTER:f}" == "5.544445"
    assert sim.DT == 0.016
    assert sim.PI == 3.14159265


def test_startup_spawns_turtle1_at_centre_with_log_line():
    world, clock, logs = make_world()
    assert list(world.turtles) == ["turtle1"]
    assert logs["info"] == ["Spawning turtle [turtle1] at x=[5.544445], y=[5.544445], theta=[0.000000]"]
    pose = run(world, clock, 1)["turtle1"].pose
    assert pose == (sim.CENTER, sim.CENTER, 0.0, 0.0, 0.0)


def test_first_tick_publishes_nothing():
    world = sim.TurtleFrame(clock=Clock())
    assert world.tick() == ([], False)
    updates, _ = world.tick()
    assert [u.name for u in updates] == ["turtle1"]


def test_straight_line_closed_form():
    world, clock, _ = make_world()
    world.turtles["turtle1"].command_velocity(1.5, 0.0, 0.0, clock())
    pose = run(world, clock, 50)["turtle1"].pose
    assert pose.x == pytest.approx(sim.CENTER + 50 * 0.016 * 1.5, abs=1e-9)
    assert pose.y == pytest.approx(sim.CENTER, abs=1e-9)
    assert pose.linear_velocity == 1.5 and pose.angular_velocity == 0.0


def test_arc_matches_closed_form_sum():
    # orientation is updated before position: x_N = x0 + v dt sum_{k=1..N} cos(k a), a = w dt.
    v, w, n = 2.0, 1.0, 40
    world, clock, _ = make_world()
    world.turtles["turtle1"].command_velocity(v, 0.0, w, clock())
    pose = run(world, clock, n)["turtle1"].pose
    a = w * sim.DT
    sum_cos = math.sin(n * a / 2) * math.cos((n + 1) * a / 2) / math.sin(a / 2)
    sum_sin = math.sin(n * a / 2) * math.sin((n + 1) * a / 2) / math.sin(a / 2)
    assert pose.theta == pytest.approx(n * a, abs=1e-12)
    assert pose.x == pytest.approx(sim.CENTER + v * sim.DT * sum_cos, abs=1e-9)
    assert pose.y == pytest.approx(sim.CENTER + v * sim.DT * sum_sin, abs=1e-9)


def test_reverse_and_sideways_report_speed_magnitude():
    world, clock, _ = make_world()
    world.turtles["turtle1"].command_velocity(-3.0, 4.0, 0.0, clock())
    pose = run(world, clock, 10)["turtle1"].pose
    assert pose.linear_velocity == 5.0  # sqrt(vx^2 + vy^2), never negative
    assert pose.x == pytest.approx(sim.CENTER - 3.0 * 0.16)
    assert pose.y == pytest.approx(sim.CENTER + 4.0 * 0.16)  # +vy is to the turtle's left


def test_command_times_out_after_one_second_of_wall_time():
    world, clock, _ = make_world()
    turtle = world.turtles["turtle1"]
    turtle.command_velocity(1.0, 0.0, 0.5, clock())
    clock.now += 1.0  # exactly 1 s: still valid (the test is "> 1.0")
    pose = world.tick()[0][0].pose
    assert pose.linear_velocity == 1.0
    clock.now += 0.001
    moved_x = turtle.x
    pose = world.tick()[0][0].pose
    assert (pose.linear_velocity, pose.angular_velocity) == (0.0, 0.0)
    assert turtle.x == moved_x


def test_orientation_wraps_to_minus_pi_pi():
    world, clock, _ = make_world()
    turtle = world.turtles["turtle1"]
    turtle.command_velocity(0.0, 0.0, 10.0, clock())
    thetas = [run(world, clock, 1)["turtle1"].pose.theta for _ in range(60)]  # 0.96 s: inside the timeout
    assert all(-sim.PI <= t < sim.PI for t in thetas)
    expected = 60 * 10.0 * sim.DT
    expected -= 2 * sim.PI * math.floor((expected + sim.PI) / (2 * sim.PI))
    assert thetas[-1] == pytest.approx(expected, abs=1e-9)


def test_wall_clamps_with_exact_warning_in_qt_coordinates():
    world, clock, logs = make_world()
    turtle = world.turtles["turtle1"]
    turtle.orient = math.pi / 2  # heading up: Qt y decreases below 0
    turtle.command_velocity(400.0, 0.0, 0.0, clock())
    pose = run(world, clock, 1)["turtle1"].pose
    y_qt = sim.CENTER - 400.0 * sim.DT * math.sin(math.pi / 2)
    assert logs["warn"] == [sim.WALL_WARNING % (turtle.x, y_qt)]
    assert logs["warn"][0].startswith("Oh no! I hit the wall! (Clamping from [x=5.544445, y=-0.855555")
    assert pose.y == sim.CANVAS_METERS and turtle.y_qt == 0.0
    turtle.orient = 0.0
    turtle.command_velocity(-400.0, 0.0, 0.0, clock())
    pose = run(world, clock, 1)["turtle1"].pose
    assert pose.x == 0.0
    assert "[x=-0.855555" in logs["warn"][-1]


def test_teleports_are_applied_on_the_next_tick_in_order():
    world, clock, _ = make_world()
    turtle = world.turtles["turtle1"]
    turtle.teleport_absolute(1.0, 2.0, 4.0)
    turtle.teleport_relative(1.0, 0.5)
    assert (turtle.x, turtle.orient) == (sim.CENTER, 0.0)  # queued only
    pose = run(world, clock, 1)["turtle1"].pose
    orient = 4.0 + 0.5
    orient -= 2 * sim.PI * math.floor((orient + sim.PI) / (2 * sim.PI))
    assert pose.x == pytest.approx(1.0 + math.cos(4.5) * 1.0)
    assert pose.y == pytest.approx(2.0 + math.sin(4.5) * 1.0)
    assert pose.theta == pytest.approx(orient)
    assert turtle.teleports == []


def test_teleport_absolute_above_the_canvas_clamps_qt_y_to_zero():
    world, clock, logs = make_world()
    world.turtles["turtle1"].teleport_absolute(3.0, 50.0, 0.0)
    pose = run(world, clock, 1)["turtle1"].pose
    assert pose.y == sim.CANVAS_METERS
    assert logs["warn"] == []


def test_pen_draws_and_colour_sensor_sees_it():
    world, clock, _ = make_world()
    turtle = world.turtles["turtle1"]
    assert run(world, clock, 1)["turtle1"].color == sim.DEFAULT_BACKGROUND
    turtle.command_velocity(1.0, 0.0, 0.0, clock())
    assert run(world, clock, 20)["turtle1"].color == sim.DEFAULT_PEN_COLOR
    row = sim._qround(turtle.y_qt * sim.METER)
    painted = np.all(world.path.pixels[row] == sim.DEFAULT_PEN_COLOR, axis=1).nonzero()[0]
    assert painted.min() <= round(sim.CENTER * sim.METER) + 1
    assert painted.max() >= round(turtle.x * sim.METER) - 1


def test_set_pen_width_zero_means_one_and_off_keeps_colour():
    turtle = sim.Turtle("t", 1.0, 1.0, 0.0)
    turtle.set_pen(10, 20, 30, 0, 0)
    assert (turtle.pen_color, turtle.pen_width, turtle.pen_on) == ((10, 20, 30), 1, True)
    turtle.set_pen(1, 2, 3, 7, 1)
    assert (turtle.pen_color, turtle.pen_width, turtle.pen_on) == ((10, 20, 30), 1, False)
    turtle.set_pen(1, 2, 3, 7, 0)
    assert (turtle.pen_color, turtle.pen_width, turtle.pen_on) == ((1, 2, 3), 7, True)


def test_pen_off_leaves_the_canvas_untouched():
    world, clock, _ = make_world()
    turtle = world.turtles["turtle1"]
    turtle.set_pen(255, 0, 0, 5, 1)
    before = world.path.pixels.copy()
    turtle.teleport_absolute(1.0, 1.0, 0.0)
    turtle.command_velocity(2.0, 0.0, 1.0, clock())
    update = run(world, clock, 30)["turtle1"]
    assert np.array_equal(before, world.path.pixels)
    assert update.color == sim.DEFAULT_BACKGROUND


def test_spawn_names_counter_and_duplicates():
    world, clock, logs = make_world()
    assert world.spawn("turtle3", 1, 1, 0) == "turtle3"
    assert world.spawn("", 2, 2, 0) == "turtle2"
    assert world.spawn("", 2, 2, 0) == "turtle4"  # counter skips the existing turtle3
    assert world.spawn("turtle2", 3, 3, 0) == ""
    assert logs["error"] == ["A turtled named [turtle2] already exists"]
    assert sorted(run(world, clock, 1)) == ["turtle1", "turtle2", "turtle3", "turtle4"]
    assert world.turtles["turtle3"].pose().y == pytest.approx(1.0)


def test_spawn_values_are_float32_like_the_cpp_arguments():
    world, _, logs = make_world()
    world.spawn("f", 0.1, 0.2, 0.3)
    assert world.turtles["f"].x == float(np.float32(0.1))
    assert logs["info"][-1] == "Spawning turtle [f] at x=[0.100000], y=[0.200000], theta=[0.300000]"


def test_kill_unknown_is_an_error_and_kill_removes():
    world, clock, logs = make_world()
    assert world.kill("nobody") is False
    assert logs["error"] == ["Tried to kill turtle [nobody], which does not exist"]
    assert world.kill("turtle1") is True
    assert run(world, clock, 1) == {}


def test_reset_and_clear():
    world, clock, _ = make_world()
    world.spawn("", 1, 1, 0)
    world.turtles["turtle1"].teleport_absolute(1.0, 1.0, 0.0)
    run(world, clock, 1)
    assert not np.all(world.path.pixels == sim.DEFAULT_BACKGROUND)
    world.clear((1, 2, 3))
    assert np.all(world.path.pixels == (1, 2, 3))
    assert world.reset() == "turtle1"
    assert list(world.turtles) == ["turtle1"] and world.id_counter == 1
    assert np.all(world.path.pixels == sim.DEFAULT_BACKGROUND)


def test_legal_turtle_names():
    assert sim.is_legal_turtle_name("turtle1")
    assert sim.is_legal_turtle_name("my_turtle/inner")
    for bad in ("", "1turtle", "a b", "a//b", "a/", "tört"):
        assert not sim.is_legal_turtle_name(bad), bad


def test_render_draws_turtles_over_the_path_image():
    world, _, _ = make_world()
    frame = world.render()
    assert frame.shape == (500, 500, 3)
    centre = round(sim.CENTER * sim.METER)
    assert not np.array_equal(frame[centre - 10:centre + 10, centre - 10:centre + 10],
                              world.path.pixels[centre - 10:centre + 10, centre - 10:centre + 10])
    assert np.array_equal(frame[:50, :50], world.path.pixels[:50, :50])


# -- the tools' ROS-free parts ------------------------------------------------------------------


def test_teleop_keys():
    assert BANNER.splitlines() == ["Reading from keyboard", "---------------------------",
                                   "Use arrow keys to move the turtle. 'q' to quit."]
    assert key_to_motion(0x41) == (2.0, 0.0)
    assert key_to_motion(0x42) == (-2.0, 0.0)
    assert key_to_motion(0x43) == (0.0, -2.0)
    assert key_to_motion(0x44, a_scale=0.5) == (0.0, 0.5)
    assert key_to_motion(ord("x")) is None and key_to_motion(ord("q")) == "quit"
    stream = iter([b"\x1b", b"[", b"A", b"x", b"\x1b", b"[", b"D", b"q", b"A"])
    sent = []
    assert key_loop(lambda: next(stream), lambda lin, ang: sent.append((lin, ang))) == "quit"
    assert sent == [(2.0, 0.0), (0.0, 2.0)]  # ESC and '[' publish nothing; stops at q
    assert key_loop(lambda: b"", lambda lin, ang: None) == "eof"


def test_mimic_copies_velocities():
    pose = sim.PoseState(1.0, 2.0, 3.0, 1.25, -0.5)
    twist = twist_for_pose(pose)
    assert (twist.linear.x, twist.angular.z, twist.linear.y) == (1.25, -0.5, 0.0)


def test_draw_square_driver_closes_the_square_on_the_simulator():
    world, clock, _ = make_world()
    turtle = world.turtles["turtle1"]
    driver = SquareDriver()
    pose = None
    states = []
    for _ in range(4000):
        command = driver.step(pose)
        if command is not None:
            turtle.command_velocity(command[0], 0.0, command[1], clock())
        pose = run(world, clock, 1)["turtle1"].pose
        if not states or states[-1] != driver.state:
            states.append(driver.state)
    assert states[:5] == [FORWARD, STOP_FORWARD, TURN, STOP_TURN, FORWARD]
    assert states.count(TURN) >= 4  # went round at least once
    assert all(sim.CENTER - 0.2 <= v <= sim.CENTER + 2.2 for v in (pose.x, pose.y))


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_commands_are_refused_and_the_turtle_survives(bad):
    world, clock, _ = make_world()
    turtle = world.turtles["turtle1"]
    with pytest.raises(sim.NonFiniteError, match=r"\[turtle1\] cmd_vel: non-finite value \(angular_z="):
        turtle.command_velocity(1.0, 0.0, bad, clock())
    with pytest.raises(sim.NonFiniteError, match="teleport_absolute"):
        turtle.teleport_absolute(bad, 1.0, 0.0)
    with pytest.raises(sim.NonFiniteError, match="teleport_relative"):
        turtle.teleport_relative(1.0, bad)
    counter = world.id_counter
    with pytest.raises(sim.NonFiniteError, match="spawn"):
        world.spawn("", 1.0, bad, 0.0)
    assert world.id_counter == counter and list(world.turtles) == ["turtle1"]
    pose = run(world, clock, 2)["turtle1"].pose
    assert all(math.isfinite(v) for v in pose) and pose.linear_velocity == 0.0
