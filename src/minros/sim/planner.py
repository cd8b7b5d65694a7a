"""move_base's pieces, small: the inflated costmap, A* over it, and a path follower.

**Costmap** (costmap_2d's conventions): a map cell at or above the lethal threshold is
``LETHAL`` (254); a cell whose centre lies within the robot's radius of a lethal cell is
``INSCRIBED`` (253: the robot's centre there would put the robot in the wall); further out,
up to ``inflation_radius``, the cost decays as ``252 * exp(-cost_scaling_factor * (d -
robot_radius))`` so that paths keep off walls; unknown map cells are ``NO_INFORMATION`` (255),
which the planner may cross unless unknown space is tracked (navfn's ``allow_unknown``).
Laser points can be marked as extra lethal cells for one planning round (no memory).

**A*** over the 8-connected grid: a step costs its length times ``1 + cost_factor * cost /
252``, so paths prefer the middle of corridors; cells of cost 253 and 254 are not entered
(except around the start, so a robot standing close to a wall can leave it). The heuristic is
the octile distance, which never overestimates, so the path is the cheapest one.

**Follower**: pure pursuit towards a point ``lookahead`` metres along the path, turning in place
first when that point lies far off the robot's heading; within ``xy_tolerance`` of the goal it
turns to the goal's heading and is done within ``yaw_tolerance``. It stops when a laser point
lies in the corridor the robot is about to drive through.

**Progress** (move_base's executive, its clocks and recovery list): a goal makes no progress
when the follower finds no valid command for ``controller_patience`` seconds, or when the
robot moves less than ``oscillation_distance`` in ``oscillation_timeout`` seconds; then the
recovery behaviours run one at a time (move_base's default list: clear the marked obstacles
farther than ``conservative_reset_dist``, rotate in place, clear all but those within four
robot radii, rotate), each followed by a new plan; when they are used up the goal is aborted
with the reason. A valid command (or enough motion, for the oscillation clock) starts the
list again from the top, as in move_base.

This is a teaching stack: no dynamic window, no rolling local costmap, no clearing by
raytracing. It is not the ROS navigation stack.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, field
from typing import List, Sequence, Tuple

import numpy as np

from minros.sim.grid import GridMap
from minros.sim.kinematics import wrap_angle

FREE = 0
INSCRIBED = 253
LETHAL = 254
NO_INFORMATION = 255

Point = Tuple[float, float]


# -- the costmap -----------------------------------------------------------------------------


@dataclass
class CostmapParams:
    """costmap_2d's parameters that matter here (names as in move_base's YAML files)."""

    robot_radius: float = 0.105
    inflation_radius: float = 1.0
    cost_scaling_factor: float = 3.0
    lethal_cost_threshold: int = 100
    track_unknown_space: bool = False


def inflate(grid: GridMap, params: CostmapParams,
            marks: Sequence[Point] = ()) -> np.ndarray:
    """The costmap (uint8, the grid's shape) of ``grid`` plus lethal ``marks`` (world points)."""
    import cv2

    lethal = grid.data.astype(np.int16) >= params.lethal_cost_threshold
    if len(marks):
        pts = np.asarray(marks, dtype=float)
        gx, gy = grid.to_cells(pts[:, 0], pts[:, 1])
        cols, rows = np.floor(gx).astype(int), np.floor(gy).astype(int)
        inside = (cols >= 0) & (cols < grid.width) & (rows >= 0) & (rows < grid.height)
        lethal = lethal.copy()
        lethal[rows[inside], cols[inside]] = True
    cost = np.zeros(grid.data.shape, dtype=np.uint8)
    if lethal.any():
        dist = cv2.distanceTransform((~lethal).astype(np.uint8), cv2.DIST_L2,
                                     cv2.DIST_MASK_PRECISE).astype(np.float64) * grid.resolution
        inscribed = dist <= params.robot_radius
        ring = ~inscribed & (dist <= params.inflation_radius)
        decay = 252.0 * np.exp(-params.cost_scaling_factor * (dist[ring] - params.robot_radius))
        cost[ring] = decay.astype(np.uint8)
        cost[inscribed] = INSCRIBED
        cost[lethal] = LETHAL
    unknown = (grid.data == -1) & (cost == FREE)
    cost[unknown] = NO_INFORMATION
    return cost


def costmap_to_occupancy(cost: np.ndarray) -> np.ndarray:
    """costmap_2d's translation of costs to OccupancyGrid values (for ``~costmap`` topics):
    0 -> 0, 253 -> 99, 254 -> 100, 255 -> -1, 1..252 -> 1 + 97 * (cost - 1) / 251."""
    c = cost.astype(np.int32)
    out = 1 + (97 * (c - 1)) // 251
    out[c == 0] = 0
    out[c == INSCRIBED] = 99
    out[c == LETHAL] = 100
    out[c == NO_INFORMATION] = -1
    return out.astype(np.int8)


# -- A* ---------------------------------------------------------------------------------------


class NoPath(Exception):
    """No path exists; the message says why in words a user can act on. ``about_goal`` is
    True when the goal itself is unreachable (off the map, in an obstacle), which no
    recovery can change."""

    def __init__(self, message: str, about_goal: bool = False) -> None:
        super().__init__(message)
        self.about_goal = about_goal


@dataclass
class PlannerParams:
    cost_factor: float = 3.0
    allow_unknown: bool = True
    #: expansions before giving up (bounds the time a hopeless search takes)
    max_expansions: int = 2_000_000


_SQRT2 = math.sqrt(2.0)


def astar(cost: np.ndarray, start: Tuple[int, int], goal: Tuple[int, int],
          params: PlannerParams = PlannerParams(), start_clearance: int = 0) -> List[Tuple[int, int]]:
    """The cheapest 8-connected path of (row, col) cells from ``start`` to ``goal``.

    ``start_clearance`` cells around the start may be crossed even when inscribed (not lethal).
    Raises :class:`NoPath` naming the reason."""
    height, width = cost.shape
    (sr, sc), (gr, gc) = start, goal
    for what, (r, c) in (("start", start), ("goal", goal)):
        if not (0 <= r < height and 0 <= c < width):
            raise NoPath(f"the {what} is outside the map", about_goal=what == "goal")
    blocked_at = int(cost[gr, gc])
    if blocked_at >= INSCRIBED and not (blocked_at == NO_INFORMATION and params.allow_unknown):
        raise NoPath("the goal is in an obstacle, or closer to one than the robot's radius"
                     if blocked_at != NO_INFORMATION else "the goal is in unknown space",
                     about_goal=True)
    if cost[sr, sc] == LETHAL:
        raise NoPath("the robot's position is inside an obstacle on the map")
    flat = cost.ravel().tolist()
    passable = [True] * (256)
    passable[INSCRIBED] = passable[LETHAL] = False
    passable[NO_INFORMATION] = params.allow_unknown
    # weight of entering a cell: 1 + factor * cost / 252 (unknown counts as free)
    weight = [1.0 + params.cost_factor * min(c, 252) / 252.0 if c != NO_INFORMATION else 1.0
              for c in range(256)]
    clear = set()
    if start_clearance > 0:
        for r in range(max(0, sr - start_clearance), min(height, sr + start_clearance + 1)):
            for c in range(max(0, sc - start_clearance), min(width, sc + start_clearance + 1)):
                if (r - sr) ** 2 + (c - sc) ** 2 <= start_clearance ** 2 and flat[r * width + c] != LETHAL:
                    clear.add(r * width + c)
    start_i, goal_i = sr * width + sc, gr * width + gc
    g = {start_i: 0.0}
    parent = {start_i: -1}
    closed = set()

    def h(i: int) -> float:
        dr, dc = abs(i // width - gr), abs(i % width - gc)
        return (dr + dc) + (_SQRT2 - 2.0) * min(dr, dc)

    steps = ((-1, 0, 1.0), (1, 0, 1.0), (0, -1, 1.0), (0, 1, 1.0),
             (-1, -1, _SQRT2), (-1, 1, _SQRT2), (1, -1, _SQRT2), (1, 1, _SQRT2))
    heap = [(h(start_i), 0.0, start_i)]
    expansions = 0
    while heap:
        _f, gi, i = heapq.heappop(heap)
        if i in closed:
            continue
        if i == goal_i:
            break
        closed.add(i)
        expansions += 1
        if expansions > params.max_expansions:
            raise NoPath(f"the search gave up after {params.max_expansions} cells")
        r, c = divmod(i, width)
        for dr, dc, length in steps:
            nr, nc = r + dr, c + dc
            if not (0 <= nr < height and 0 <= nc < width):
                continue
            j = nr * width + nc
            cj = flat[j]
            if not passable[cj] and j not in clear:
                continue
            if dr and dc:  # no corner cutting between two blocked cells
                a, b = flat[r * width + nc], flat[nr * width + c]
                if (not passable[a] and (r * width + nc) not in clear) and \
                        (not passable[b] and (nr * width + c) not in clear):
                    continue
            ng = gi + length * weight[cj]
            if ng < g.get(j, math.inf):
                g[j] = ng
                parent[j] = i
                heapq.heappush(heap, (ng + h(j), ng, j))
    else:
        raise NoPath("no way through the obstacles from the robot to the goal")
    cells = []
    i = goal_i
    while i != -1:
        cells.append(divmod(i, width))
        i = parent[i]
    cells.reverse()
    return cells


def plan(grid: GridMap, cost: np.ndarray, start: Point, goal: Point,
         params: PlannerParams = PlannerParams(), robot_radius: float = 0.105) -> List[Point]:
    """A* between two world points; the path in world coordinates, from start to goal exactly."""
    for what, point in (("robot", start), ("goal", goal)):
        if not all(math.isfinite(v) for v in point):
            raise NoPath(f"the {what} ({point[0]}, {point[1]}) is not a finite position",
                         about_goal=what == "goal")
    s = grid.cell_of(*start)
    if s is None:
        raise NoPath(f"the robot ({start[0]:.2f}, {start[1]:.2f}) is outside the map")
    t = grid.cell_of(*goal)
    if t is None:
        raise NoPath(f"the goal ({goal[0]:.2f}, {goal[1]:.2f}) is outside the map", about_goal=True)
    clearance = int(math.ceil(robot_radius / grid.resolution)) + 1
    cells = astar(cost, s, t, params, start_clearance=clearance)
    rows = np.array([rc[0] for rc in cells], dtype=float) + 0.5
    cols = np.array([rc[1] for rc in cells], dtype=float) + 0.5
    xs, ys = grid.to_world(cols, rows)
    points = [(float(x), float(y)) for x, y in zip(xs, ys)]
    points[0] = (float(start[0]), float(start[1]))
    if len(points) == 1:
        points.append((float(goal[0]), float(goal[1])))
    else:
        points[-1] = (float(goal[0]), float(goal[1]))
    return points


# -- the follower ------------------------------------------------------------------------------


@dataclass
class FollowerParams:
    max_vel_x: float = 0.22
    max_vel_theta: float = 1.5
    min_in_place_vel_theta: float = 0.3
    acc_lim_x: float = 2.5  # m/s^2, limits how fast the forward speed grows
    lookahead: float = 0.35
    xy_goal_tolerance: float = 0.08
    yaw_goal_tolerance: float = 0.17
    rotate_threshold: float = 0.9  # turn in place when the heading error exceeds this (rad)
    robot_radius: float = 0.105
    safety_margin: float = 0.05
    stop_time: float = 0.6  # seconds of driving the obstacle check looks ahead


@dataclass
class Follower:
    """Follows one path; :meth:`step` is called at the controller frequency."""

    path: List[Point]
    goal_yaw: float
    params: FollowerParams = field(default_factory=FollowerParams)
    index: int = 0
    xy_reached: bool = False
    last_v: float = 0.0
    #: the nearest laser point (robot frame) that blocked the last step, for the reason
    blocking: Point | None = None

    def remaining(self, x: float, y: float) -> float:
        gx, gy = self.path[-1]
        return math.hypot(gx - x, gy - y)

    def step(self, x: float, y: float, yaw: float, dt: float,
             obstacles: np.ndarray | None = None) -> Tuple[float, float, str]:
        """The command (v, w) for the robot at (x, y, yaw), and a state:
        ``"done"``, ``"rotating"``, ``"driving"`` or ``"blocked"``.
        ``obstacles`` are laser points in the robot's frame (N x 2) or None."""
        p = self.params
        gx, gy = self.path[-1]
        if self.xy_reached or math.hypot(gx - x, gy - y) <= p.xy_goal_tolerance:
            self.xy_reached = True
            error = wrap_angle(self.goal_yaw - yaw)
            if abs(error) <= p.yaw_goal_tolerance:
                self.last_v = 0.0
                return 0.0, 0.0, "done"
            self.last_v = 0.0
            return 0.0, self._turn(error), "rotating"
        tx, ty = self._lookahead_point(x, y)
        distance = math.hypot(tx - x, ty - y)
        alpha = wrap_angle(math.atan2(ty - y, tx - x) - yaw)
        if abs(alpha) > p.rotate_threshold:
            self.last_v = 0.0
            return 0.0, self._turn(alpha), "rotating"
        goal_distance = math.hypot(gx - x, gy - y)
        v = p.max_vel_x * (1.0 - 0.6 * abs(alpha) / p.rotate_threshold)
        v = min(v, max(0.05, 1.2 * goal_distance), self.last_v + p.acc_lim_x * dt)
        w = 2.0 * v * math.sin(alpha) / max(distance, 1e-3)
        w = max(-p.max_vel_theta, min(p.max_vel_theta, w))
        if obstacles is not None and self._blocked(obstacles, v, goal_distance):
            self.last_v = 0.0
            return 0.0, 0.0, "blocked"
        self.last_v = v
        return v, w, "driving"

    def _lookahead_point(self, x: float, y: float) -> Point:
        """The point ``lookahead`` metres along the path past the robot's projection on it
        (the projection never moves back along the path)."""
        path = self.path
        if len(path) == 1:
            return path[0]
        best_i, best_d, best_p = self.index, math.inf, path[self.index]
        for i in range(self.index, min(len(path) - 1, self.index + 200)):
            (ax, ay), (bx, by) = path[i], path[i + 1]
            dx, dy = bx - ax, by - ay
            length2 = dx * dx + dy * dy
            s = 0.0 if length2 == 0 else max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / length2))
            px, py = ax + s * dx, ay + s * dy
            d = (px - x) ** 2 + (py - y) ** 2
            if d < best_d:
                best_i, best_d, best_p = i, d, (px, py)
        self.index = best_i
        remaining, point, i = self.params.lookahead, best_p, best_i
        while i < len(path) - 1:
            nx, ny = path[i + 1]
            step = math.hypot(nx - point[0], ny - point[1])
            if step >= remaining:
                f = remaining / step
                return point[0] + f * (nx - point[0]), point[1] + f * (ny - point[1])
            remaining -= step
            point, i = (nx, ny), i + 1
        return path[-1]

    def _turn(self, error: float) -> float:
        p = self.params
        speed = max(p.min_in_place_vel_theta, min(p.max_vel_theta, 1.5 * abs(error)))
        return math.copysign(speed, error)

    def _blocked(self, points: np.ndarray, v: float, goal_distance: float) -> bool:
        """Whether a laser point lies in the corridor swept by driving ahead for stop_time
        (but not beyond where the robot's front will be at the goal: a wall behind the goal
        is not in the way)."""
        p = self.params
        if len(points) == 0:
            return False
        half = p.robot_radius + p.safety_margin
        reach = p.robot_radius + p.safety_margin + max(v, 0.05) * p.stop_time
        reach = min(reach, goal_distance + p.robot_radius + 0.01)
        ahead = (points[:, 0] > 0.0) & (points[:, 0] < reach) & (np.abs(points[:, 1]) < half)
        if not ahead.any():
            return False
        inside = points[ahead]
        nearest = int(np.argmin(np.hypot(inside[:, 0], inside[:, 1])))
        self.blocking = (float(inside[nearest, 0]), float(inside[nearest, 1]))
        return True


# -- progress and recovery ---------------------------------------------------------------------


@dataclass
class ProgressParams:
    """move_base's names. The defaults are move_base's, except the oscillation clock, which
    move_base leaves off (``oscillation_timeout`` 0) and TurtleBot3's navigation configuration
    (move_base_params.yaml) sets to 10 s and 0.2 m: a teaching stack should end every goal."""

    controller_patience: float = 15.0
    oscillation_timeout: float = 10.0
    oscillation_distance: float = 0.2
    recovery_behavior_enabled: bool = True
    clearing_rotation_allowed: bool = True
    conservative_reset_dist: float = 3.0


@dataclass(frozen=True)
class Recovery:
    """One recovery behaviour: ``clear`` (forget marked obstacles outside the square of side
    ``reset_distance`` around the robot, as clear_costmap_recovery) or ``rotate`` (turn once
    in place, as rotate_recovery)."""

    name: str
    kind: str
    reset_distance: float = 0.0


def recovery_behaviors(params: ProgressParams, robot_radius: float) -> List[Recovery]:
    """move_base's default list (its loadDefaultRecoveryBehaviors), in its order; the
    aggressive reset keeps what lies within four robot radii, as move_base sizes it."""
    out = [Recovery("conservative_reset", "clear", params.conservative_reset_dist)]
    if params.clearing_rotation_allowed:
        out.append(Recovery("rotate_recovery", "rotate"))
    out.append(Recovery("aggressive_reset", "clear", 4.0 * robot_radius))
    if params.clearing_rotation_allowed:
        out.append(Recovery("rotate_recovery", "rotate"))
    return out


def clear_marks(marks: Sequence[Point], x: float, y: float,
                reset_distance: float) -> List[Point]:
    """The marks clear_costmap_recovery keeps: those inside the axis-aligned square of side
    ``reset_distance`` centred on the robot at (x, y)."""
    half = reset_distance / 2.0
    return [(mx, my) for mx, my in marks if abs(mx - x) <= half and abs(my - y) <= half]


#: what the goal is aborted with when the recoveries are used up, by what triggered them
EXHAUSTED = {
    "planning": "Failed to find a valid plan. Even after executing recovery behaviors.",
    "controlling": "Failed to find a valid control. Even after executing recovery behaviors.",
    "oscillation": "Robot is oscillating. Even after executing recovery behaviors.",
}


class Progress:
    """move_base's clocks of no progress and its place in the recovery list, for one goal.

    Pure: the caller passes the time (seconds, any clock) and the robot's position. The
    executive calls :meth:`controlled` after each valid command, :meth:`moved` every cycle,
    asks :meth:`control_failed` after an invalid one and :meth:`oscillating` while
    controlling, then :meth:`next_recovery` with the trigger (None means abort with
    ``EXHAUSTED[trigger]``) and :meth:`recovered` once the behaviour has run."""

    def __init__(self, params: ProgressParams, robot_radius: float, now: float) -> None:
        self.params = params
        self.behaviors = recovery_behaviors(params, robot_radius)
        self.reset(now)

    def reset(self, now: float) -> None:
        """A new goal: every clock starts now and the recovery list from its top."""
        self.last_valid_control = now
        self.last_oscillation_reset = now
        self.oscillation_pose: Point | None = None
        self.index = 0
        self.trigger: str | None = None

    def moved(self, now: float, x: float, y: float) -> None:
        if self.oscillation_pose is None:
            self.oscillation_pose = (x, y)
            return
        ox, oy = self.oscillation_pose
        if math.hypot(x - ox, y - oy) >= self.params.oscillation_distance:
            self.oscillation_pose = (x, y)
            self.last_oscillation_reset = now
            if self.trigger == "oscillation":
                self.index = 0

    def controlled(self, now: float) -> None:
        self.last_valid_control = now
        if self.trigger == "controlling":
            self.index = 0

    def planned(self) -> None:
        if self.trigger == "planning":
            self.index = 0

    def control_failed(self, now: float) -> bool:
        """Whether the controller has been without a valid command beyond its patience."""
        return now - self.last_valid_control > self.params.controller_patience

    def oscillating(self, now: float) -> bool:
        timeout = self.params.oscillation_timeout
        return timeout > 0 and now - self.last_oscillation_reset > timeout

    def next_recovery(self, trigger: str) -> Recovery | None:
        """The behaviour to run for ``trigger`` ("planning", "controlling", "oscillation"),
        or None when recovery is off or every behaviour has been tried."""
        self.trigger = trigger
        if not self.params.recovery_behavior_enabled or self.index >= len(self.behaviors):
            return None
        behavior = self.behaviors[self.index]
        self.index += 1
        return behavior

    def recovered(self, now: float) -> None:
        """A behaviour has run: the robot gets time to stop oscillating, as in move_base."""
        self.last_oscillation_reset = now


# -- goals -------------------------------------------------------------------------------------


def quaternion_problem(x: float, y: float, z: float, w: float) -> str | None:
    """move_base's isQuaternionValid as a reason (None when the quaternion is usable)."""
    if not all(math.isfinite(v) for v in (x, y, z, w)):
        return "Quaternion has nans or infs... discarding as a navigation goal"
    n2 = x * x + y * y + z * z + w * w
    if n2 < 1e-6:
        return "Quaternion has length close to zero... discarding as navigation goal"
    n = math.sqrt(n2)
    x, y, z, w = x / n, y / n, z / n, w / n
    # z component of the rotated up vector: 1 - 2(x^2 + y^2)
    if abs((1.0 - 2.0 * (x * x + y * y)) - 1.0) > 1e-3:
        return ("Quaternion is invalid... for navigation the z-axis of the quaternion must be "
                "close to vertical.")
    return None


def position_problem(x: float, y: float, z: float) -> str | None:
    """Why a goal position cannot be used (None when it can): the companion of
    :func:`quaternion_problem`, which move_base lacks (its planner turns a NaN into a cell)."""
    if not all(math.isfinite(v) for v in (x, y, z)):
        return f"(x={x}, y={y}, z={z}): the position has nans or infs"
    return None


def yaw_of(x: float, y: float, z: float, w: float) -> float:
    """The heading (rotation about z) of a quaternion."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def path_length(path: Sequence[Point]) -> float:
    return sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(path, path[1:]))
