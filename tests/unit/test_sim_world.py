"""The simulated world without ROS: ray casting, kinematics, collisions, scans, the picture."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from minros.sim import kinematics, mapfile
from minros.sim.grid import GridMap
from minros.sim.raycast import RayCaster, cast_discs, scan_angles
from minros.sim.render import Renderer
from minros.sim.world import RANGE_MAX, Robot, World, WorldError


def box_world(width=100, height=80, resolution=0.05, origin=(0.0, 0.0, 0.0)) -> GridMap:
    data = np.zeros((height, width), np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    return GridMap(data, resolution, origin)


def brute_range(grid: GridMap, walls, x, y, angle, max_range, step=1e-4):
    """The first wall along the ray, by walking it in 0.1 mm steps (the slow oracle)."""
    t = 0.0
    while t <= max_range:
        gx, gy = grid.to_cells(x + t * math.cos(angle), y + t * math.sin(angle))
        col, row = math.floor(float(gx)), math.floor(float(gy))
        if not (0 <= col < grid.width and 0 <= row < grid.height):
            return math.inf
        if walls[row, col]:
            return t
        t += step
    return math.inf


@pytest.fixture(scope="module")
def cluttered():
    rng = np.random.default_rng(7)
    walls = rng.random((60, 70)) < 0.04
    walls[0, :] = walls[-1, :] = walls[:, 0] = walls[:, -1] = True
    grid = GridMap(np.where(walls, 100, 0).astype(np.int8), 0.05, (-1.0, -0.5, 0.3))
    return grid, walls, RayCaster(grid, walls)


@settings(max_examples=60, deadline=None)
@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(-math.pi, math.pi))
def test_ray_casting_matches_walking_the_ray(cluttered, fx, fy, angle):
    grid, walls, caster = cluttered
    x0, y0, x1, y1 = grid.bounds()
    x, y = x0 + fx * (x1 - x0), y0 + fy * (y1 - y0)
    cell = grid.cell_of(x, y)
    if cell is None or walls[cell]:
        return
    got = caster.cast(np.array([x]), np.array([y]), np.array([angle]), 2.0)[0]
    want = brute_range(grid, walls, x, y, angle, 2.0)
    if math.isinf(want):
        # the walker may step over a corner the exact traversal clips
        assert math.isinf(got) or got <= 2.0
    else:
        assert got <= want + 2e-4
        assert got >= want - 0.01 or _clips_corner(grid, walls, x, y, angle, got)


def _clips_corner(grid, walls, x, y, angle, t):
    gx, gy = grid.to_cells(x + (t + 1e-7) * math.cos(angle), y + (t + 1e-7) * math.sin(angle))
    return bool(walls[math.floor(float(gy)), math.floor(float(gx))])


def test_ranges_are_exact_against_an_axis_aligned_wall():
    grid = box_world()
    caster = RayCaster(grid, grid.walls())
    # from x = 1.0 towards +x: the wall cells start at col 99, x = 4.95
    ranges = caster.cast(np.array([1.0, 1.0, 1.0]), np.array([1.0, 1.0, 1.0]),
                         np.array([0.0, math.pi / 2, math.pi]), 10.0)
    assert ranges == pytest.approx([3.95, 2.95, 0.95], abs=1e-5)
    assert caster.cast(np.array([1.0]), np.array([1.0]), np.array([0.0]), 3.0)[0] == math.inf


def test_discs_are_seen_and_a_robot_does_not_see_itself():
    centres = np.array([[0.0, 0.0], [2.0, 0.0]])
    radii = np.array([0.1, 0.5])
    t = cast_discs(np.array([0.0, 0.0]), np.array([0.0, 0.0]), np.array([0.0, math.pi]),
                   centres, radii, np.array([0, 0]))
    assert t[0] == pytest.approx(1.5) and t[1] == math.inf


def test_arc_integration_is_exact():
    # a full circle of radius v / w in many steps or one comes back to the start
    x = y = yaw = 0.0
    for _ in range(100):
        x, y, yaw = kinematics.integrate(x, y, yaw, 0.2, 2 * math.pi / 10, 0.1)
    assert (x, y, yaw) == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
    assert kinematics.integrate(1.0, 2.0, math.pi / 2, 0.5, 0.0, 2.0) == pytest.approx((1.0, 3.0, math.pi / 2))
    assert kinematics.Limits().clamp(1.0, -9.0) == (0.22, -2.84)


def test_robots_stop_at_walls_and_at_each_other_but_may_turn():
    world = World(box_world())
    a = world.add_robot(Robot("a", 1.0, 1.0, 0.0))
    world.add_robot(Robot("b", 1.5, 1.0, 0.0))
    for _ in range(40):
        world.command("a", 0.2, 0.0)
        world.step(0.05)
    assert a.stalled and a.actual_v == 0.0
    assert 0.21 - 0.011 <= math.hypot(a.x - 1.5, a.y - 1.0) and a.x < 1.5 - 0.21 + 1e-9
    x = a.x
    world.command("a", 0.0, 1.0)  # pressed against b it may still turn
    world.step(0.05)
    assert a.x == x and a.yaw == pytest.approx(0.05)
    # towards the wall at x = 4.95: stops with its disc outside the wall cells
    world.command("b", 0.22, 0.0)
    for _ in range(400):
        world.command("b", 0.22, 0.0)
        world.step(0.05)
    b = world.robots["b"]
    assert b.stalled and 4.95 - 0.105 - 0.01 < b.x <= 4.95 - 0.105


def test_bad_commands_and_places_are_refused_in_one_line():
    world = World(box_world())
    world.add_robot(Robot("a", 1.0, 1.0, 0.0))
    with pytest.raises(WorldError, match="non-finite velocity command"):
        world.command("a", float("nan"), 0.0)
    with pytest.raises(WorldError, match="cannot start at"):
        world.add_robot(Robot("wall", 0.02, 1.0, 0.0))
    with pytest.raises(WorldError, match="already a robot named"):
        world.add_robot(Robot("a", 2.0, 2.0, 0.0))


def test_the_watchdog_stops_a_robot_without_commands():
    world = World(box_world(), command_timeout=0.5)
    robot = world.add_robot(Robot("", 1.0, 1.0, 0.0))
    world.command("", 0.2, 0.0)
    for _ in range(20):  # 1 s
        world.step(0.05)
    assert robot.x == pytest.approx(1.0 + 0.2 * 0.5, abs=0.011)
    assert robot.v == 0.0


def test_scans_follow_rep117_and_see_other_robots():
    world = World(box_world())
    world.add_robot(Robot("a", 2.0, 1.0, 0.0))
    world.add_robot(Robot("b", 2.0, 1.6, 0.0))
    scans = world.scan()
    a = scans["a"]
    assert a.dtype == np.float32 and a.shape == (360,)
    # beam 90 (pi/2) hits b: laser at (1.968, 1.0), b's disc at y = 1.6 - sqrt(r^2 - 0.032^2)
    assert a[90] == pytest.approx(0.6 - math.sqrt(0.105 ** 2 - 0.032 ** 2), abs=1e-5)
    assert a[0] == pytest.approx(4.95 - 1.968, abs=1e-5)
    # beyond range_max: +inf; a laser pressed against a wall: -inf (closer than range_min)
    world2 = World(box_world(width=200))
    world2.add_robot(Robot("", 0.16, 1.0, 0.0))  # its laser 7.8 cm from the wall behind it
    ranges = world2.scan()[""]
    assert ranges[180] == -math.inf
    assert ranges[0] == math.inf and RANGE_MAX < 9.95 - 0.128


def test_odometry_starts_at_zero_and_follows_the_robot():
    world = World(box_world())
    robot = world.add_robot(Robot("", 2.0, 1.0, math.pi / 2))
    world.command("", 0.2, 0.0)
    for _ in range(10):
        world.step(0.1)
    ox, oy, oyaw = robot.odometry()
    assert (ox, oy, oyaw) == pytest.approx((0.2, 0.0, 0.0), abs=1e-9)
    assert (robot.x, robot.y) == pytest.approx((2.0, 1.2))


def test_default_world_has_room_to_drive_ahead_of_the_start():
    from minros.sim.world import DEFAULT_WORLD

    grid, _ = mapfile.load_map(DEFAULT_WORLD)
    world = World(grid)
    robot = world.add_robot(Robot("", 0.0, 0.0, 0.0))
    assert world.scan()[""][0] >= 1.5 + 0.032
    # and the robot can actually drive 1.5 m straight ahead
    for _ in range(int(1.5 / 0.22 / 0.05) + 2):
        world.command("", 0.22, 0.0)
        world.step(0.05)
    assert not robot.stalled and robot.x >= 1.5


def test_render_draws_the_map_and_the_robots():
    world = World(box_world())
    world.add_robot(Robot("a", 1.0, 1.0, 0.0))
    renderer = Renderer(world)
    image = renderer.render(world.scan())
    assert image.shape == (80 * renderer.scale, 100 * renderer.scale, 3)
    px, py = (int(v) for v in renderer.pixel(0.95, 1.0))
    assert tuple(image[py, px]) != (254, 254, 254)  # the robot's colour
    assert tuple(image[2 * renderer.scale, image.shape[1] // 2]) == (254, 254, 254)  # free
    assert tuple(image[0, 0]) == (40, 40, 40)  # a wall


def test_scan_angles_are_turtlebot3s():
    angles = scan_angles()
    assert angles[0] == 0.0 and angles[1] == pytest.approx(math.pi / 180)
    assert angles[-1] == pytest.approx(2 * math.pi * 359 / 360)
