"""``rosrun move_base move_base``: a small, honest navigation node for teaching.

**This is not the ROS navigation stack.** It serves move_base's interface, so that scripts
sending navigation goals have a partner, with a planner and controller small enough to read
(:mod:`minros.sim.planner`): A* over the map inflated by the robot's radius, a pure-pursuit
follower that stops for laser points in its way, replanning around them, and move_base's
executive: when no progress is made (no valid command for ``controller_patience``, or less
than ``oscillation_distance`` travelled in ``oscillation_timeout``, or no plan), its default
recovery behaviours run in turn (clear far obstacles, rotate, clear all but the nearest,
rotate), and then the goal is aborted with the reason, so every goal ends with a status. No
costmap layers, no DWA, no AMCL; localization is whatever publishes ``map -> odom``
(``minros sim`` does, perfectly).

Interfaces, as move_base's:

* action server ``move_base`` (move_base_msgs/MoveBase): goals in any frame tf can transform
  to the global frame (``map``, ``odom``, ``base_footprint``...), transformed once when they
  arrive; SUCCEEDED "Goal reached."; ABORTED with the reason (invalid quaternion, a position
  with nans or infs, unknown frame, goal off the map or in an obstacle, no map; move_base's
  "Failed to find a valid plan/control" or "Robot is oscillating" texts after the recovery
  behaviours, followed by what was wrong in brackets);
  a new goal preempts the current one;
* ``move_base_simple/goal`` (geometry_msgs/PoseStamped): re-sent as an action goal on
  ``move_base/goal``, as move_base does (the 2D Nav Goal tool of Rviz publishes there);
* ``cmd_vel`` out; ``map`` (nav_msgs/OccupancyGrid, latched by map_server) and ``scan``
  (sensor_msgs/LaserScan) in; ``~current_goal``, ``~NavfnROS/plan`` (nav_msgs/Path) and
  ``~global_costmap/costmap`` (the inflated map, latched) out; ``~make_plan``
  (nav_msgs/GetPlan) and ``~clear_costmaps`` (std_srvs/Empty) served.

Parameters (private): ``global_costmap/global_frame`` (map), ``global_costmap/robot_base_frame``
(base_footprint), ``global_costmap/robot_radius`` (0.105, the TurtleBot3 Burger's),
``global_costmap/inflation_radius`` (1.0) and ``cost_scaling_factor`` (3.0) as TurtleBot3's
navigation configuration, ``global_costmap/lethal_cost_threshold`` (100),
``controller_frequency`` (20), ``planner_frequency`` (0: plan when needed),
``planner_patience`` (5 s without a map), ``controller_patience`` (15 s without a valid
command before recovery), ``oscillation_timeout`` (10 s) and ``oscillation_distance`` (0.2 m)
as TurtleBot3's (move_base's default timeout is 0, off), ``conservative_reset_dist`` (3.0),
``recovery_behavior_enabled`` and ``clearing_rotation_allowed`` (true), and the follower's
``max_vel_x`` (0.22),
``max_vel_theta`` (1.5), ``xy_goal_tolerance`` (0.08), ``yaw_goal_tolerance`` (0.17),
``lookahead`` (0.35).
"""

from __future__ import annotations

import math
import sys
import threading
import time
from typing import Any, List, Tuple

import numpy as np

from minros.sim import planner
from minros.sim.grid import GridMap

INVALID_QUATERNION = "Aborting on goal because it was sent with an invalid quaternion"
INVALID_POSITION = "Aborting on goal because it was sent with a non-finite position"
#: how long the follower may be blocked before it replans around what the laser sees
REPLAN_WHEN_BLOCKED = 1.0


class GoalRejected(Exception):
    """A goal that cannot be pursued; the text is what the action result carries."""


def _param(name: str, default: Any) -> Any:
    import rospy

    value = rospy.get_param("~" + name, default)
    if isinstance(default, bool):
        return bool(value)
    if isinstance(default, (int, float)) and not isinstance(default, bool):
        try:
            value = type(default)(value)
        except (TypeError, ValueError):
            rospy.logwarn(f"~{name}: {value!r} is not a number; using {default}")
            return default
    return value


class MoveBase:
    def __init__(self) -> None:
        import actionlib
        import rospy
        import tf2_geometry_msgs  # noqa: F401  (registers PoseStamped with tf2_ros)
        import tf2_ros
        from geometry_msgs.msg import PoseStamped, Twist
        from move_base_msgs.msg import MoveBaseAction, MoveBaseActionGoal
        from nav_msgs.msg import OccupancyGrid, Path
        from nav_msgs.srv import GetPlan
        from sensor_msgs.msg import LaserScan
        from std_srvs.srv import Empty

        self.global_frame = _param("global_costmap/global_frame", "map")
        self.base_frame = _param("global_costmap/robot_base_frame", "base_footprint")
        self.costmap_params = planner.CostmapParams(
            robot_radius=_param("global_costmap/robot_radius", 0.105),
            inflation_radius=_param("global_costmap/inflation_radius", 1.0),
            cost_scaling_factor=_param("global_costmap/cost_scaling_factor", 3.0),
            lethal_cost_threshold=_param("global_costmap/lethal_cost_threshold", 100),
            track_unknown_space=_param("global_costmap/track_unknown_space", False))
        self.planner_params = planner.PlannerParams(
            allow_unknown=not self.costmap_params.track_unknown_space)
        self.follower_params = planner.FollowerParams(
            max_vel_x=_param("max_vel_x", 0.22), max_vel_theta=_param("max_vel_theta", 1.5),
            xy_goal_tolerance=_param("xy_goal_tolerance", 0.08),
            yaw_goal_tolerance=_param("yaw_goal_tolerance", 0.17),
            lookahead=_param("lookahead", 0.35), robot_radius=self.costmap_params.robot_radius)
        self.controller_frequency = max(1.0, _param("controller_frequency", 20.0))
        self.planner_frequency = max(0.0, _param("planner_frequency", 0.0))
        self.planner_patience = _param("planner_patience", 5.0)
        defaults = planner.ProgressParams()
        self.progress_params = planner.ProgressParams(**{
            name: _param(name, getattr(defaults, name)) for name in (
                "controller_patience", "oscillation_timeout", "oscillation_distance",
                "recovery_behavior_enabled", "clearing_rotation_allowed",
                "conservative_reset_dist")})

        self.PoseStamped, self.Twist, self.Path = PoseStamped, Twist, Path
        self.MoveBaseActionGoal = MoveBaseActionGoal
        self.lock = threading.Lock()  # the map, the costmap and the latest scan
        self.grid: GridMap | None = None
        self.cost: np.ndarray | None = None
        self.map_frame = self.global_frame
        self.marks: List[Tuple[float, float]] = []
        self.scan: Any = None

        self.buffer = tf2_ros.Buffer()
        self.listener = tf2_ros.TransformListener(self.buffer)
        self.tf_errors = (tf2_ros.LookupException, tf2_ros.ConnectivityException,
                          tf2_ros.ExtrapolationException, tf2_ros.TransformException)
        self.vel_pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
        self.current_goal_pub = rospy.Publisher("~current_goal", PoseStamped, queue_size=1)
        self.plan_pub = rospy.Publisher("~NavfnROS/plan", Path, queue_size=1, latch=True)
        self.costmap_pub = rospy.Publisher("~global_costmap/costmap", OccupancyGrid,
                                           queue_size=1, latch=True)
        self.action_goal_pub = rospy.Publisher("move_base/goal", MoveBaseActionGoal, queue_size=1)
        self.server = actionlib.SimpleActionServer("move_base", MoveBaseAction,
                                                   execute_cb=self.execute, auto_start=False)
        self.map_sub = rospy.Subscriber("map", OccupancyGrid, self._on_map, queue_size=1)
        self.scan_sub = rospy.Subscriber("scan", LaserScan, self._on_scan, queue_size=1)
        self.simple_sub = rospy.Subscriber("move_base_simple/goal", PoseStamped,
                                           self._on_simple_goal, queue_size=1)
        self.services = [rospy.Service("~make_plan", GetPlan, self._on_make_plan),
                         rospy.Service("~clear_costmaps", Empty, self._on_clear_costmaps)]
        self.server.start()

    # -- inputs

    def _on_map(self, msg: Any) -> None:
        import rospy
        from minros.nodes.map_server.map_saver import grid_of
        from minros.nodes.map_server.map_server import occupancy_grid

        try:
            grid = grid_of(msg)
        except Exception as exc:
            rospy.logerr(f"{rospy.get_name()}: ignoring the map on {self.map_sub.resolved_name}: {exc}")
            return
        cost = planner.inflate(grid, self.costmap_params)
        with self.lock:
            self.grid, self.cost = grid, cost
            self.map_frame = msg.header.frame_id or self.global_frame
        if self.map_frame != self.global_frame:
            rospy.logwarn(f"{rospy.get_name()}: the map is in frame {self.map_frame}, not the global "
                          f"frame {self.global_frame}; plans are made in {self.map_frame}")
        costmap = occupancy_grid(GridMap(planner.costmap_to_occupancy(cost), grid.resolution,
                                         grid.origin), self.map_frame, msg.header.stamp)
        self.costmap_pub.publish(costmap)
        rospy.loginfo(f"{rospy.get_name()}: map of {grid.width} x {grid.height} cells at "
                      f"{grid.resolution:.3f} m, inflated by {self.costmap_params.robot_radius} m")

    def _on_scan(self, msg: Any) -> None:
        with self.lock:
            self.scan = msg

    def _on_simple_goal(self, msg: Any) -> None:
        import rospy

        action_goal = self.MoveBaseActionGoal()
        action_goal.header.stamp = rospy.Time.now()
        action_goal.goal.target_pose = msg
        self.action_goal_pub.publish(action_goal)

    def _on_clear_costmaps(self, _req: Any) -> Any:
        with self.lock:
            self.marks = []
        return []

    def _on_make_plan(self, req: Any) -> Any:
        import rospy

        path = self.Path()
        path.header.frame_id = self.map_frame
        path.header.stamp = rospy.Time.now()
        try:
            start = (self.robot_pose() if not req.start.header.frame_id
                     else self.to_global(req.start))
            goal = self.to_global(req.goal)
            points = self.make_plan(start[:2], goal[:2])
        except (GoalRejected, planner.NoPath) as exc:
            rospy.logerr(f"move_base cannot make a plan: {exc}")
            return [path]
        path.poses = self.poses(points, goal[2], path.header.stamp)
        return [path]

    # -- geometry

    @staticmethod
    def check_position(pose_stamped: Any) -> None:
        """GoalRejected for a position with nans or infs (before tf or the planner sees it)."""
        p = pose_stamped.pose.position
        problem = planner.position_problem(p.x, p.y, p.z)
        if problem:
            raise GoalRejected(f"{INVALID_POSITION} {problem}; discarding it as a navigation goal")

    def to_global(self, pose_stamped: Any) -> Tuple[float, float, float]:
        """(x, y, yaw) of a PoseStamped in the map frame, with the latest transform."""
        import rospy

        self.check_position(pose_stamped)
        source = pose_stamped.header.frame_id
        if not source:
            raise GoalRejected("The goal pose has no frame_id: set header.frame_id (e.g. map)")
        latest = self.PoseStamped()
        latest.header.frame_id = source
        latest.header.stamp = rospy.Time(0)  # the latest transform, as move_base takes it
        latest.pose = pose_stamped.pose
        try:
            out = self.buffer.transform(latest, self.map_frame, rospy.Duration(0.5))
        except self.tf_errors as exc:
            text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            raise GoalRejected(f"Failed to transform the goal pose from {source} into the "
                               f"{self.map_frame} frame: {text}") from None
        q = out.pose.orientation
        return out.pose.position.x, out.pose.position.y, planner.yaw_of(q.x, q.y, q.z, q.w)

    def robot_pose(self) -> Tuple[float, float, float]:
        import rospy

        try:
            t = self.buffer.lookup_transform(self.map_frame, self.base_frame, rospy.Time(0),
                                             rospy.Duration(0.2))
        except self.tf_errors as exc:
            raise GoalRejected(f"cannot get the robot's pose ({self.map_frame} -> "
                               f"{self.base_frame}): {str(exc).strip()}") from None
        r = t.transform.rotation
        return (t.transform.translation.x, t.transform.translation.y,
                planner.yaw_of(r.x, r.y, r.z, r.w))

    def obstacles(self, pose: Tuple[float, float, float]) -> np.ndarray | None:
        """The latest scan's points in the robot's base frame (N x 2), or None."""
        import rospy

        with self.lock:
            scan = self.scan
        if scan is None:
            return None
        try:
            t = self.buffer.lookup_transform(self.base_frame, scan.header.frame_id,
                                             rospy.Time(0), rospy.Duration(0.05))
        except self.tf_errors:
            return None
        ranges = np.asarray(scan.ranges, dtype=float)
        angles = scan.angle_min + scan.angle_increment * np.arange(ranges.size)
        ok = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
        r = t.transform.rotation
        yaw = planner.yaw_of(r.x, r.y, r.z, r.w)
        a = angles[ok] + yaw
        xs = t.transform.translation.x + ranges[ok] * np.cos(a)
        ys = t.transform.translation.y + ranges[ok] * np.sin(a)
        return np.column_stack([xs, ys])

    def make_plan(self, start: Tuple[float, float], goal: Tuple[float, float],
                  marks: List[Tuple[float, float]] | None = None) -> List[Tuple[float, float]]:
        with self.lock:
            grid, cost = self.grid, self.cost
            extra = list(self.marks) if marks is None else marks
        if grid is None or cost is None:
            raise GoalRejected("move_base has no map: is map_server publishing on "
                               f"{self.map_sub.resolved_name}?")
        if extra:
            cost = planner.inflate(grid, self.costmap_params, extra)
        return planner.plan(grid, cost, start, goal, self.planner_params,
                            self.costmap_params.robot_radius)

    def poses(self, points: List[Tuple[float, float]], goal_yaw: float, stamp: Any) -> List[Any]:
        out = []
        for i, (x, y) in enumerate(points):
            p = self.PoseStamped()
            p.header.frame_id = self.map_frame
            p.header.stamp = stamp
            p.pose.position.x, p.pose.position.y = x, y
            if i + 1 < len(points):
                yaw = math.atan2(points[i + 1][1] - y, points[i + 1][0] - x)
            else:
                yaw = goal_yaw
            p.pose.orientation.z, p.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
            out.append(p)
        return out

    # -- the action

    def stop(self) -> None:
        self.vel_pub.publish(self.Twist())

    def wait_for_map(self) -> bool:
        import rospy

        deadline = time.monotonic() + self.planner_patience
        while not rospy.is_shutdown() and time.monotonic() < deadline:
            with self.lock:
                if self.grid is not None:
                    return True
            time.sleep(0.05)
        with self.lock:
            return self.grid is not None

    def accept(self, goal: Any) -> Tuple[float, float, float]:
        """Check a goal and bring it into the map frame; GoalRejected says why not."""
        import rospy

        q = goal.target_pose.pose.orientation
        problem = planner.quaternion_problem(q.x, q.y, q.z, q.w)
        if problem:
            hint = " (set orientation.w: 1.0 for a heading of 0)" if "zero" in problem else ""
            rospy.logerr(problem + hint)
            raise GoalRejected(INVALID_QUATERNION)
        self.check_position(goal.target_pose)
        if not self.wait_for_map():
            raise GoalRejected("move_base has no map: is map_server publishing on "
                               f"{self.map_sub.resolved_name}?")
        target = self.to_global(goal.target_pose)
        p = self.PoseStamped()
        p.header.frame_id = self.map_frame
        p.header.stamp = rospy.Time.now()
        p.pose.position.x, p.pose.position.y = target[0], target[1]
        p.pose.orientation.z, p.pose.orientation.w = math.sin(target[2] / 2), math.cos(target[2] / 2)
        self.current_goal_pub.publish(p)
        rospy.loginfo(f"{rospy.get_name()}: new goal ({target[0]:.2f}, {target[1]:.2f}, "
                      f"{math.degrees(target[2]):.0f} deg) in {self.map_frame}")
        return target

    def execute(self, goal: Any) -> None:
        import rospy

        try:
            self._execute(goal)
        except rospy.ROSInterruptException:  # shutting down while sleeping in the loop
            pass

    def _execute(self, goal: Any) -> None:
        import rospy
        from move_base_msgs.msg import MoveBaseFeedback, MoveBaseResult

        try:
            target = self.accept(goal)
        except GoalRejected as exc:
            self._abort(str(exc))
            return
        self.stop()
        rate = rospy.Rate(self.controller_frequency)
        dt = 1.0 / self.controller_frequency
        now = rospy.get_time
        state = "planning"
        follower: planner.Follower | None = None
        blocked_since: float | None = None
        progress = planner.Progress(self.progress_params, self.costmap_params.robot_radius, now())
        why, trigger = "", "controlling"  # what went wrong last, for the abort's text
        marks: List[Tuple[float, float]] = []
        last_plan = now()
        while not rospy.is_shutdown():
            if self.server.is_preempt_requested():
                if self.server.is_new_goal_available():
                    goal = self.server.accept_new_goal()
                    try:
                        target = self.accept(goal)
                    except GoalRejected as exc:
                        self._abort(str(exc))
                        return
                    state, marks, blocked_since = "planning", [], None
                    progress.reset(now())
                else:
                    self.stop()
                    self.server.set_preempted()
                    return
            try:
                pose = self.robot_pose()
            except GoalRejected as exc:
                self.stop()
                if progress.control_failed(now()):
                    self._abort(str(exc))
                    return
                rospy.logwarn_throttle(2.0, f"{rospy.get_name()}: {exc}")
                rate.sleep()
                continue
            progress.moved(now(), pose[0], pose[1])
            if state == "planning":
                try:
                    path = self.make_plan(pose[:2], target[:2], marks)
                except GoalRejected as exc:
                    self._abort(str(exc))
                    return
                except planner.NoPath as exc:
                    if exc.about_goal:
                        self._abort(f"No path to the goal: {exc}")
                        return
                    why, trigger, state = str(exc), "planning", "recovery"
                else:
                    follower = planner.Follower(path, target[2], self.follower_params)
                    self.plan_pub.publish(self._path_msg(path, target[2]))
                    rospy.loginfo(f"{rospy.get_name()}: plan of {planner.path_length(path):.2f} m")
                    progress.planned()
                    state, last_plan = "controlling", now()
            if state == "controlling" and follower is not None:
                t = now()
                if progress.oscillating(t):
                    self.stop()
                    why = (f"it moved less than {self.progress_params.oscillation_distance} m "
                           f"in {self.progress_params.oscillation_timeout} s")
                    trigger, state = "oscillation", "recovery"
            if state == "controlling" and follower is not None:
                v, w, status = follower.step(pose[0], pose[1], pose[2], dt, self.obstacles(pose))
                self._feedback(MoveBaseFeedback(), pose)
                if status == "done":
                    self.stop()
                    rospy.loginfo(f"{rospy.get_name()}: Goal reached.")
                    self.server.set_succeeded(MoveBaseResult(), "Goal reached.")
                    return
                t = now()
                if status == "blocked":
                    self.stop()
                    if progress.control_failed(t):
                        why = self._blocked_reason(follower, t - progress.last_valid_control)
                        trigger, state = "controlling", "recovery"
                    else:
                        blocked_since = blocked_since or t
                        if t - blocked_since > REPLAN_WHEN_BLOCKED:
                            # plan around what the laser sees now (in the map frame)
                            marks = self._marks(pose)
                            blocked_since = None
                            state = "planning"
                else:
                    blocked_since = None
                    progress.controlled(t)
                    cmd = self.Twist()
                    cmd.linear.x, cmd.angular.z = v, w
                    self.vel_pub.publish(cmd)
                    if self.planner_frequency > 0 and t - last_plan > 1.0 / self.planner_frequency:
                        state = "planning"
            if state == "recovery":
                behavior = progress.next_recovery(trigger)
                if behavior is None:
                    self._abort(f"{planner.EXHAUSTED[trigger]} ({why})")
                    return
                rospy.logwarn(f"{rospy.get_name()}: no progress ({why}); recovery "
                              f"{progress.index} of {len(progress.behaviors)}: {behavior.name}")
                if behavior.kind == "rotate":
                    if not self._rotate_recovery():
                        continue  # preempted or shut down: the loop's top handles it
                else:
                    marks = planner.clear_marks(marks, pose[0], pose[1], behavior.reset_distance)
                    with self.lock:
                        self.marks = list(marks)
                progress.recovered(now())
                state, blocked_since = "planning", None
                continue
            rate.sleep()
        self.stop()
        if self.server.is_active():
            self.server.set_aborted(MoveBaseResult(),
                                    "Aborting on the goal because the node has been killed")

    def _feedback(self, feedback: Any, pose: Tuple[float, float, float]) -> None:
        import rospy

        feedback.base_position.header.frame_id = self.map_frame
        feedback.base_position.header.stamp = rospy.Time.now()
        feedback.base_position.pose.position.x = pose[0]
        feedback.base_position.pose.position.y = pose[1]
        feedback.base_position.pose.orientation.z = math.sin(pose[2] / 2)
        feedback.base_position.pose.orientation.w = math.cos(pose[2] / 2)
        self.server.publish_feedback(feedback)

    def _blocked_reason(self, follower: planner.Follower, seconds: float) -> str:
        where = ""
        if follower.blocking is not None:
            bx, by = follower.blocking
            where = (f": a laser point {math.hypot(bx, by):.2f} m from the robot ({bx:+.2f}, "
                     f"{by:+.2f} in {self.base_frame}) is in its way")
        return f"no valid velocity command for {seconds:.1f} s{where}"

    def _marks(self, pose: Tuple[float, float, float]) -> List[Tuple[float, float]]:
        points = self.obstacles(pose)
        if points is None or len(points) == 0:
            return []
        c, s = math.cos(pose[2]), math.sin(pose[2])
        xs = pose[0] + c * points[:, 0] - s * points[:, 1]
        ys = pose[1] + s * points[:, 0] + c * points[:, 1]
        marks = list(zip(xs.tolist(), ys.tolist()))
        with self.lock:
            self.marks = marks
        return marks

    def _rotate_recovery(self) -> bool:
        """Turn once in place (rotate_recovery); False if preempted or shut down meanwhile."""
        import rospy

        speed = min(1.0, self.follower_params.max_vel_theta)
        rate = rospy.Rate(self.controller_frequency)
        end = rospy.Time.now() + rospy.Duration(2.0 * math.pi / speed)
        cmd = self.Twist()
        cmd.angular.z = speed
        while not rospy.is_shutdown() and rospy.Time.now() < end:
            if self.server.is_preempt_requested():
                self.stop()
                return False
            self.vel_pub.publish(cmd)
            rate.sleep()
        self.stop()
        return not rospy.is_shutdown()

    def _abort(self, text: str) -> None:
        import rospy
        from move_base_msgs.msg import MoveBaseResult

        self.stop()
        rospy.logerr(f"{rospy.get_name()}: {text}")
        self.server.set_aborted(MoveBaseResult(), text)

    def _path_msg(self, points: List[Tuple[float, float]], goal_yaw: float) -> Any:
        import rospy

        path = self.Path()
        path.header.frame_id = self.map_frame
        path.header.stamp = rospy.Time.now()
        path.poses = self.poses(points, goal_yaw, path.header.stamp)
        return path


def main(argv: List[str] | None = None) -> int:
    import rospy

    full_argv = list(sys.argv if argv is None else argv)
    extra = rospy.myargv(full_argv)[1:]
    if extra and extra[0] in ("-h", "--help"):
        print((__doc__ or "").strip())
        return 0
    rospy.init_node("move_base", argv=full_argv)
    MoveBase()
    rospy.loginfo("move_base (minros's teaching version) is ready: send goals to "
                  f"{rospy.resolve_name('move_base')} or "
                  f"{rospy.resolve_name('move_base_simple/goal')}")
    rospy.spin()
    return 0


if __name__ == "__main__":
    from minros.nodes.turtlesim import run_tool

    sys.exit(run_tool("move_base", main))
