"""The simulated world: differential-drive robots on a map, their collisions and lasers.

Each robot is a disc (the TurtleBot3 Burger's footprint radius, 0.105 m) at its ground-truth
pose in the map frame. A step moves every robot along its commanded arc; a robot whose new
position would overlap a wall, the edge of the map or another robot stays where it was
(turning in place is always allowed: a disc that turns covers the same cells) and is marked
stalled, as Stage stalls a robot. The laser sits where the Burger's LDS sits (3.2 cm behind
the centre) and sees the walls and the other robots.

Odometry is perfect: each robot's odom frame is its starting pose, so odom -> base_footprint
is the ground truth relative to the start, and map -> odom is the start pose itself.
Everything here is driven step by step from tests; the ROS node is :mod:`minros.nodes.minros_sim`.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Dict, List, Sequence, Tuple

import numpy as np

from minros.sim import kinematics
from minros.sim.grid import WALL_THRESHOLD, GridMap
from minros.sim.raycast import RayCaster, cast_discs, scan_angles

#: TurtleBot3 Burger: footprint radius (costmap_common_params_burger.yaml's robot_radius),
#: base_footprint -> base_scan offset (turtlebot3_burger.urdf.xacro) and its LDS-01's range
ROBOT_RADIUS = 0.105
LASER_OFFSET = (-0.032, 0.0, 0.182)
RANGE_MIN = 0.12
RANGE_MAX = 3.5
BEAMS = 360
#: minros sim's default world: three rooms, 10 m x 8 m, drawn by scripts/sim_world.py
DEFAULT_WORLD = os.path.join(os.path.dirname(os.path.abspath(__file__)), "share", "worlds",
                             "rooms.yaml")


class WorldError(ValueError):
    """A request the world cannot honour (a robot placed in a wall, a duplicate name...)."""


@dataclass
class Laser:
    """A 2D laser: ``beams`` rays from ``angle_min``, one ``increment`` apart."""

    beams: int = BEAMS
    angle_min: float = 0.0
    increment: float = 2.0 * math.pi / BEAMS
    range_min: float = RANGE_MIN
    range_max: float = RANGE_MAX
    offset: Tuple[float, float] = (LASER_OFFSET[0], LASER_OFFSET[1])
    noise: float = 0.0  # standard deviation of Gaussian range noise, metres

    @property
    def angle_max(self) -> float:
        return self.angle_min + self.increment * (self.beams - 1)

    def angles(self) -> np.ndarray:
        return scan_angles(self.beams, self.angle_min, self.increment)


@dataclass
class Robot:
    """One robot: its ground truth, its command and what odometry reports."""

    name: str
    x: float
    y: float
    yaw: float
    radius: float = ROBOT_RADIUS
    limits: kinematics.Limits = field(default_factory=kinematics.Limits)
    laser: Laser = field(default_factory=Laser)
    # the command being executed (clamped) and when it was given (simulated seconds)
    v: float = 0.0
    w: float = 0.0
    command_time: float = -math.inf
    stalled: bool = False
    # the speeds actually achieved in the last step (zero while stalled)
    actual_v: float = 0.0
    actual_w: float = 0.0
    wheel_left: float = 0.0
    wheel_right: float = 0.0
    start: Tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        self.start = (self.x, self.y, self.yaw)

    def odometry(self) -> Tuple[float, float, float]:
        """The pose in the robot's odom frame (its start pose is the odom origin)."""
        sx, sy, syaw = self.start
        dx, dy = self.x - sx, self.y - sy
        c, s = math.cos(syaw), math.sin(syaw)
        return c * dx + s * dy, -s * dx + c * dy, kinematics.wrap_angle(self.yaw - syaw)

    def laser_pose(self) -> Tuple[float, float, float]:
        ox, oy = self.laser.offset
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return self.x + c * ox - s * oy, self.y + s * ox + c * oy, self.yaw


class World:
    """Robots on a grid map. ``time`` is simulated seconds since the start."""

    def __init__(self, grid: GridMap, wall_threshold: int = WALL_THRESHOLD,
                 command_timeout: float = 0.0, seed: int | None = None) -> None:
        self.grid = grid
        self.walls = grid.walls(wall_threshold)
        self.caster = RayCaster(grid, self.walls)
        self.robots: Dict[str, Robot] = {}
        self.time = 0.0
        #: a robot stops when its last command is older than this (simulated s); 0 = never
        self.command_timeout = command_timeout
        self._rng = np.random.default_rng(seed)

    # -- robots

    def add_robot(self, robot: Robot) -> Robot:
        if robot.name in self.robots:
            raise WorldError(f"there is already a robot named {robot.name!r}")
        for value in (robot.x, robot.y, robot.yaw):
            if not math.isfinite(value):
                raise WorldError(f"robot {robot.name!r}: its pose must be finite numbers")
        if self.collides(robot.x, robot.y, robot.radius, exclude=robot.name):
            raise WorldError(
                f"robot {robot.name or 'robot'} cannot start at ({robot.x:.2f}, {robot.y:.2f}): "
                "that place is inside a wall, off the map or on another robot; choose a free pose")
        self.robots[robot.name] = robot
        return robot

    def command(self, name: str, v: float, w: float) -> None:
        """Set robot ``name``'s velocity command (clamped to its limits); NaN/inf rejected."""
        if not (math.isfinite(v) and math.isfinite(w)):
            raise WorldError(f"non-finite velocity command (linear.x={v}, angular.z={w}) ignored")
        robot = self.robots[name]
        robot.v, robot.w = robot.limits.clamp(v, w)
        robot.command_time = self.time

    def reset(self) -> None:
        """Every robot back to its start pose, standing still (stageros's reset_positions)."""
        for robot in self.robots.values():
            robot.x, robot.y, robot.yaw = robot.start
            robot.v = robot.w = robot.actual_v = robot.actual_w = 0.0
            robot.stalled = False

    # -- collisions

    def collides(self, x: float, y: float, radius: float, exclude: str | None = None) -> bool:
        """Whether a disc at (x, y) overlaps a wall, leaves the map or overlaps a robot."""
        for other in self.robots.values():
            if other.name != exclude and math.hypot(other.x - x, other.y - y) < radius + other.radius:
                return True
        return self.hits_wall(x, y, radius)

    def hits_wall(self, x: float, y: float, radius: float) -> bool:
        grid = self.grid
        gx, gy = (float(v) for v in grid.to_cells(x, y))
        r = radius / grid.resolution
        c0, c1 = math.floor(gx - r), math.floor(gx + r)
        r0, r1 = math.floor(gy - r), math.floor(gy + r)
        if c0 < 0 or r0 < 0 or c1 >= grid.width or r1 >= grid.height:
            return True  # the edge of the map is a wall
        window = self.walls[r0:r1 + 1, c0:c1 + 1]
        if not window.any():
            return False
        rows, cols = np.nonzero(window)
        # the point of each wall square nearest to the centre
        near_x = np.clip(gx, cols + c0, cols + c0 + 1.0)
        near_y = np.clip(gy, rows + r0, rows + r0 + 1.0)
        return bool((((near_x - gx) ** 2 + (near_y - gy) ** 2) < r * r).any())

    # -- time

    def step(self, dt: float) -> None:
        """Advance ``dt`` simulated seconds: move every robot along its command."""
        self.time += dt
        for robot in self.robots.values():
            if self.command_timeout > 0 and self.time - robot.command_time > self.command_timeout:
                robot.v = robot.w = 0.0
            x, y, yaw = kinematics.integrate(robot.x, robot.y, robot.yaw, robot.v, robot.w, dt)
            moved = (x, y) != (robot.x, robot.y)
            if moved and self.collides(x, y, robot.radius, exclude=robot.name):
                robot.stalled = True
                robot.actual_v = 0.0
                x, y = robot.x, robot.y  # stay; turning in place is still possible
            else:
                robot.stalled = False
                robot.actual_v = robot.v
            robot.actual_w = robot.w
            robot.x, robot.y, robot.yaw = x, y, yaw
            left, right = kinematics.wheel_speeds(robot.actual_v, robot.actual_w)
            robot.wheel_left = kinematics.wrap_angle(robot.wheel_left + left * dt)
            robot.wheel_right = kinematics.wrap_angle(robot.wheel_right + right * dt)

    # -- sensing

    def scan(self, names: Sequence[str] | None = None) -> Dict[str, np.ndarray]:
        """Each named robot's laser ranges (float32, one per beam): ``inf`` beyond range_max,
        ``-inf`` closer than range_min (REP 117), walls and other robots seen."""
        robots = [self.robots[n] for n in (self.robots if names is None else names)]
        if not robots:
            return {}
        origins_x: List[np.ndarray] = []
        origins_y: List[np.ndarray] = []
        angles: List[np.ndarray] = []
        owner: List[np.ndarray] = []
        everyone = list(self.robots.values())
        index_of = {r.name: i for i, r in enumerate(everyone)}
        max_range = max(r.laser.range_max for r in robots)
        for robot in robots:
            lx, ly, lyaw = robot.laser_pose()
            beams = robot.laser.angles() + lyaw
            angles.append(beams)
            origins_x.append(np.full(beams.size, lx))
            origins_y.append(np.full(beams.size, ly))
            owner.append(np.full(beams.size, index_of[robot.name]))
        ox, oy, ang = np.concatenate(origins_x), np.concatenate(origins_y), np.concatenate(angles)
        ranges = self.caster.cast(ox, oy, ang, max_range)
        if len(everyone) > 1:
            centres = np.array([(r.x, r.y) for r in everyone])
            radii = np.array([r.radius for r in everyone])
            ranges = np.minimum(ranges, cast_discs(ox, oy, ang, centres, radii,
                                                   np.concatenate(owner)))
        out: Dict[str, np.ndarray] = {}
        start = 0
        for robot in robots:
            laser = robot.laser
            r = ranges[start:start + laser.beams].copy()
            start += laser.beams
            if laser.noise > 0:
                finite = np.isfinite(r)
                r[finite] += self._rng.normal(0.0, laser.noise, int(finite.sum()))
            r[r > laser.range_max] = np.inf
            r[r < laser.range_min] = -np.inf
            out[robot.name] = r.astype(np.float32)
        return out

    def free_pose_near(self, x: float, y: float, radius: float = ROBOT_RADIUS,
                       search: float = 2.0) -> Tuple[float, float] | None:
        """The free place nearest to (x, y) within ``search`` metres (a grid of candidates)."""
        step = max(self.grid.resolution, 0.05)
        best = None
        for ring in range(int(search / step) + 1):
            for i in range(-ring, ring + 1):
                for j in range(-ring, ring + 1):
                    if max(abs(i), abs(j)) != ring:
                        continue
                    cx, cy = x + i * step, y + j * step
                    if not self.collides(cx, cy, radius):
                        d = math.hypot(cx - x, cy - y)
                        if best is None or d < best[0]:
                            best = (d, cx, cy)
            if best is not None:
                return best[1], best[2]
        return None
