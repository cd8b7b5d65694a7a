"""move_base's pieces without ROS: the inflated costmap, A*, the follower driving a simulated
robot in closed loop, and move_base's goal checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from minros.sim import mapfile, planner
from minros.sim.grid import GridMap
from minros.sim.world import Robot, World


@pytest.fixture(scope="module")
def rooms():
    from minros.sim.world import DEFAULT_WORLD

    grid, _ = mapfile.load_map(DEFAULT_WORLD)
    return grid


def corridor(width_cells: int) -> GridMap:
    """A 2 m long corridor ``width_cells`` cells wide between two walls (0.05 m cells)."""
    data = np.full((width_cells + 2, 40), 0, np.int8)
    data[0, :] = data[-1, :] = 100
    return GridMap(data, 0.05)


def test_inflation_follows_costmap_2d():
    grid = corridor(20)
    params = planner.CostmapParams(robot_radius=0.105, inflation_radius=0.3, cost_scaling_factor=3.0)
    cost = planner.inflate(grid, params)
    column = cost[:, 5].tolist()
    assert column[0] == planner.LETHAL
    # cell centres 0.05 and 0.10 m from the wall's centre are within the radius: inscribed
    assert column[1] == column[2] == planner.INSCRIBED
    d = 0.15  # next: 252 * exp(-3 * (0.15 - 0.105))
    assert column[3] == int(252 * math.exp(-3.0 * (d - 0.105)))
    assert column[11] == 0  # 0.55 m from both walls: beyond the inflation radius
    occupancy = planner.costmap_to_occupancy(np.array([0, 1, 128, 252, 253, 254, 255], np.uint8))
    assert occupancy.tolist() == [0, 1, 1 + 97 * 127 // 251, 98, 99, 100, -1]


def test_unknown_cells_and_marks():
    data = np.zeros((10, 10), np.int8)
    data[5, 5] = -1
    grid = GridMap(data, 0.1)
    cost = planner.inflate(grid, planner.CostmapParams(robot_radius=0.1, inflation_radius=0.2),
                           marks=[(0.25, 0.25)])
    assert cost[5, 5] == planner.NO_INFORMATION
    assert cost[2, 2] == planner.LETHAL and cost[2, 3] == planner.INSCRIBED


def test_astar_finds_the_cheapest_path_and_never_cuts_corners():
    cost = np.zeros((5, 5), np.uint8)
    cost[1:4, 2] = planner.LETHAL
    cells = planner.astar(cost, (2, 0), (2, 4))
    assert cells[0] == (2, 0) and cells[-1] == (2, 4)
    assert all(cost[r, c] < planner.INSCRIBED for r, c in cells)
    # around the wall's end through row 0 or row 4: four diagonal steps
    assert len(cells) == 5 and cells[2][0] in (0, 4)
    # two blocked cells touching at a corner cannot be squeezed through diagonally
    cost = np.zeros((3, 3), np.uint8)
    cost[0, 1] = cost[1, 0] = planner.LETHAL
    cost[1, 2] = cost[2, 1] = planner.LETHAL
    with pytest.raises(planner.NoPath, match="no way through") as info:
        planner.astar(cost, (0, 0), (2, 2))
    assert not info.value.about_goal


def test_no_path_reasons(rooms):
    cost = planner.inflate(rooms, planner.CostmapParams())
    with pytest.raises(planner.NoPath, match="outside the map") as info:
        planner.plan(rooms, cost, (0.0, 0.0), (40.0, 0.0))
    assert info.value.about_goal
    with pytest.raises(planner.NoPath, match="in an obstacle") as info:
        planner.plan(rooms, cost, (0.0, 0.0), (4.0, -2.1))  # inside the box in the east room
    assert info.value.about_goal
    # a goal enclosed by walls: a ring around (0, 0)
    data = np.zeros((40, 40), np.int8)
    data[10:30, 10] = data[10:30, 29] = data[10, 10:30] = data[29, 10:30] = 100
    grid = GridMap(data, 0.05)
    with pytest.raises(planner.NoPath, match="no way through") as info:
        planner.plan(grid, planner.inflate(grid, planner.CostmapParams()), (0.2, 0.2), (1.0, 1.0))
    assert not info.value.about_goal


def test_plans_start_and_end_exactly_and_go_through_the_door(rooms):
    cost = planner.inflate(rooms, planner.CostmapParams())
    path = planner.plan(rooms, cost, (0.0, 0.0), (4.0, 0.0))
    assert path[0] == (0.0, 0.0) and path[-1] == (4.0, 0.0)
    # the east room's wall (x = 2.5) has its door at y 1..2
    crossing = [y for (x0, y), (x1, _) in zip(path, path[1:]) if x0 < 2.5 <= x1]
    assert len(crossing) == 1 and 1.1 < crossing[0] < 1.9
    assert 5.0 < planner.path_length(path) < 6.5


def test_a_robot_next_to_a_wall_can_still_leave_it():
    grid = corridor(20)
    cost = planner.inflate(grid, planner.CostmapParams())
    path = planner.plan(grid, cost, (0.5, 0.17), (1.5, 0.5))  # 0.12 m from the wall's edge
    assert path[-1] == (1.5, 0.5)


def drive(world: World, name: str, follower: planner.Follower, seconds: float, dt: float = 0.05):
    """Close the loop in simulation: follower -> world -> pose, until done or out of time."""
    robot = world.robots[name]
    status = ""
    for _ in range(int(seconds / dt)):
        ranges = world.scan([name])[name]
        angles = robot.laser.angles()
        ok = np.isfinite(ranges)
        points = np.column_stack([robot.laser.offset[0] + ranges[ok] * np.cos(angles[ok]),
                                  ranges[ok] * np.sin(angles[ok])])
        v, w, status = follower.step(robot.x, robot.y, robot.yaw, dt, points)
        if status == "done":
            break
        world.command(name, v, w)
        world.step(dt)
    return status


@pytest.mark.slow  # over half a CPU-second of its own
@pytest.mark.parametrize("goal", [(4.0, 0.0, math.pi / 2), (-3.0, -3.0, math.pi), (-2.5, 3.0, 0.0)])
def test_the_follower_drives_a_simulated_robot_to_the_goal(rooms, goal):
    world = World(rooms)
    robot = world.add_robot(Robot("", 0.0, 0.0, 0.0))
    cost = planner.inflate(rooms, planner.CostmapParams())
    path = planner.plan(rooms, cost, (0.0, 0.0), goal[:2])
    follower = planner.Follower(path, goal[2])
    stalls = 0
    status = drive(world, "", follower, 90.0)
    stalls += robot.stalled
    assert status == "done"
    assert math.hypot(robot.x - goal[0], robot.y - goal[1]) <= follower.params.xy_goal_tolerance + 0.02
    assert abs(math.remainder(robot.yaw - goal[2], 2 * math.pi)) <= follower.params.yaw_goal_tolerance
    assert not stalls


def test_the_follower_stops_for_what_the_laser_sees():
    grid = corridor(20)
    world = World(grid)
    world.add_robot(Robot("r", 0.3, 0.5, 0.0))
    world.add_robot(Robot("obstacle", 1.0, 0.5, 0.0))
    follower = planner.Follower([(0.3, 0.5), (1.8, 0.5)], 0.0)
    assert drive(world, "r", follower, 5.0) == "blocked"
    r = world.robots["r"]
    assert not r.stalled and r.x < 1.0 - 0.21 - 0.02  # stopped short of touching


def test_a_goal_close_to_a_wall_ahead_is_reached():
    grid = corridor(20)
    data = grid.data.copy()
    data[:, 36:] = 100  # a wall across the corridor at x = 1.8
    grid = GridMap(data, 0.05)
    world = World(grid)
    robot = world.add_robot(Robot("r", 0.3, 0.5, 0.0))
    goal = (1.8 - 0.105 - 0.04, 0.5)  # the robot's front 4 cm short of the wall
    follower = planner.Follower(planner.plan(grid, planner.inflate(grid, planner.CostmapParams()),
                                             (0.3, 0.5), goal), 0.0)
    assert drive(world, "r", follower, 20.0) == "done"
    assert math.hypot(robot.x - goal[0], robot.y - goal[1]) <= 0.1 and not robot.stalled


@pytest.mark.parametrize("q, problem", [
    ((0.0, 0.0, 0.0, 1.0), None),
    ((0.0, 0.0, 0.7071, 0.7071), None),
    ((0.0, 0.0, 0.0, 0.0), "length close to zero"),
    ((float("nan"), 0.0, 0.0, 1.0), "nans or infs"),
    ((0.7071, 0.0, 0.0, 0.7071), "z-axis of the quaternion must be close to vertical"),
])
def test_goal_quaternions_are_checked_as_move_base_does(q, problem):
    found = planner.quaternion_problem(*q)
    assert (found is None) if problem is None else (problem in found)


@pytest.mark.parametrize("goal", [(math.nan, 0.0), (0.0, math.inf), (-math.inf, math.nan)])
def test_non_finite_points_are_no_path_not_a_traceback(rooms, goal):
    cost = planner.inflate(rooms, planner.CostmapParams())
    with pytest.raises(planner.NoPath, match="not a finite position") as info:
        planner.plan(rooms, cost, (0.0, 0.0), goal)
    assert info.value.about_goal
    with pytest.raises(planner.NoPath, match="not a finite position") as info:
        planner.plan(rooms, cost, goal, (0.0, 0.0))
    assert not info.value.about_goal
    assert "nans or infs" in planner.position_problem(goal[0], goal[1], 0.0)
    assert planner.position_problem(1.0, 2.0, 0.0) is None


def test_yaw_of():
    assert planner.yaw_of(0.0, 0.0, math.sin(0.4), math.cos(0.4)) == pytest.approx(0.8)


def test_recovery_behaviors_are_move_bases_default_list():
    params = planner.ProgressParams()
    assert [(b.name, b.kind, b.reset_distance) for b in planner.recovery_behaviors(params, 0.105)] == [
        ("conservative_reset", "clear", 3.0), ("rotate_recovery", "rotate", 0.0),
        ("aggressive_reset", "clear", pytest.approx(0.42)), ("rotate_recovery", "rotate", 0.0)]
    no_turns = planner.ProgressParams(clearing_rotation_allowed=False)
    assert [b.name for b in planner.recovery_behaviors(no_turns, 0.105)] == [
        "conservative_reset", "aggressive_reset"]
    marks = [(0.1, 0.1), (1.4, -1.4), (1.6, 0.0), (-0.2, 0.25)]
    assert planner.clear_marks(marks, 0.0, 0.0, 3.0) == [(0.1, 0.1), (1.4, -1.4), (-0.2, 0.25)]
    assert planner.clear_marks(marks, 0.0, 0.0, 0.42) == [(0.1, 0.1)]


def test_progress_patience_recovery_list_and_abort():
    progress = planner.Progress(planner.ProgressParams(controller_patience=15.0), 0.105, now=100.0)
    progress.moved(100.0, 0.0, 0.0)
    assert not progress.control_failed(115.0) and progress.control_failed(115.1)
    # every behaviour once, in order; then None: abort with move_base's text
    names = []
    while (behavior := progress.next_recovery("controlling")) is not None:
        names.append(behavior.name)
        progress.recovered(116.0)
    assert len(names) == 4
    assert planner.EXHAUSTED["controlling"].startswith("Failed to find a valid control")
    # a valid command starts the list again from the top (for the trigger that used it)
    progress.controlled(120.0)
    assert progress.next_recovery("controlling").name == "conservative_reset"
    assert not progress.control_failed(130.0)
    off = planner.Progress(planner.ProgressParams(recovery_behavior_enabled=False), 0.105, 0.0)
    assert off.next_recovery("planning") is None


def test_progress_oscillation_clock():
    params = planner.ProgressParams(oscillation_timeout=10.0, oscillation_distance=0.2)
    progress = planner.Progress(params, 0.105, now=0.0)
    for t in range(0, 11):  # turning on the spot, 5 cm of drift
        progress.moved(float(t), 0.005 * t, 0.0)
    assert not progress.oscillating(10.0) and progress.oscillating(10.5)
    assert progress.next_recovery("oscillation").name == "conservative_reset"
    progress.recovered(11.0)  # the robot gets time again after each behaviour
    assert not progress.oscillating(20.0)
    progress.moved(21.0, 0.3, 0.0)  # 0.25 m from where the clock started: progress
    assert progress.index == 0 and not progress.oscillating(30.0)
    assert not planner.Progress(planner.ProgressParams(oscillation_timeout=0.0), 0.1,
                                0.0).oscillating(1e9)


def test_the_follower_says_what_blocks_it():
    follower = planner.Follower([(0.0, 0.0), (1.0, 0.0)], 0.0)
    v, w, status = follower.step(0.0, 0.0, 0.0, 0.05, np.array([[0.5, 0.0], [0.12, 0.14]]))
    assert status == "blocked" and follower.blocking == pytest.approx((0.12, 0.14))
