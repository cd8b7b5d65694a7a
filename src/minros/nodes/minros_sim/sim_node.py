"""``rosrun minros_sim sim_node [WORLD.yaml] [options]``: the 2D simulator (``minros sim``).

A world from a map_server map (YAML + image) and one or more TurtleBot3 Burger-like robots.
Per robot, under its namespace when there are several (``tb3_0/cmd_vel``, ...), as the
TurtleBot3 simulations name them:

* ``cmd_vel`` (geometry_msgs/Twist, in): clamped to the Burger's limits; a robot stops when no
  command came for ``--watchdog`` seconds (0.5 s, as the TurtleBot3 firmware);
* ``odom`` (nav_msgs/Odometry), tf ``odom -> base_footprint`` (perfect odometry), the wheels'
  ``joint_states`` and their transforms, every ``--rate`` tick;
* ``scan`` (sensor_msgs/LaserScan, frame ``base_scan``): 360 beams from 0 rad, 0.12-3.5 m,
  ``inf`` where nothing is in range, at ``--laser-rate``;
* ``base_pose_ground_truth`` (nav_msgs/Odometry in the map frame, as Stage publishes it);
* latched ``/tf_static``: ``map -> odom`` (a perfect localization, unless
  ``--no-localization``) and the robot's fixed frames; the parameter and latched topic
  ``robot_description`` (URDF) and the parameter ``tf_prefix`` when namespaced.

Frames of a namespaced robot carry its name as prefix (``tb3_0/odom``); ``map`` is shared.
The node also serves ``reset_positions`` (std_srvs/Empty, stageros's) and draws the world
top-down on ``~view`` (sensor_msgs/Image, bgr8, rendered only while someone watches), in a
window with ``--window``, or into a PNG with ``--snapshot``. ``--clock`` publishes ``/clock``
(set ``/use_sim_time`` true, as ``minros sim --clock`` does); ``--speed`` runs faster or slower
than real time (0: as fast as the machine can).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import threading
import time
from typing import Any, Dict, Iterator, List, Tuple

from minros.sim import kinematics, mapfile
from minros.sim import robot as model
from minros.sim.world import DEFAULT_WORLD, Laser, Robot, World, WorldError

#: spacing of the default start poses (metres along y)
ROW_SPACING = 0.5


def parse_pose(text: str) -> Tuple[str | None, float, float, float]:
    """``[NAME=]X,Y[,YAW]`` -> (name or None, x, y, yaw); ValueError with the reason."""
    name = None
    if "=" in text:
        name, text = text.split("=", 1)
    parts = text.split(",")
    if len(parts) not in (2, 3):
        raise ValueError(f"{text!r}: expected X,Y or X,Y,YAW")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise ValueError(f"{text!r}: X, Y and YAW must be numbers") from None
    if not all(math.isfinite(v) for v in values):
        raise ValueError(f"{text!r}: X, Y and YAW must be finite")
    x, y = values[0], values[1]
    return name, x, y, values[2] if len(values) == 3 else 0.0


def robot_names(count: int) -> List[str]:
    """One robot has no namespace; several are ``tb3_0``, ``tb3_1``, ... (TurtleBot3's)."""
    return [""] if count == 1 else [f"tb3_{i}" for i in range(count)]


def row_candidates(limit: int = 200) -> Iterator[Tuple[float, float]]:
    """Start places in a row along y through (0, 0): 0, +0.5, -0.5, +1.0, ... metres."""
    yield 0.0, 0.0
    for k in range(1, limit):
        yield 0.0, ROW_SPACING * ((k + 1) // 2) * (1 if k % 2 else -1)


def frame(prefix: str, name: str) -> str:
    return f"{prefix}/{name}" if prefix else name


def _quaternion(roll: float, pitch: float, yaw: float) -> Tuple[float, float, float, float]:
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def _multiply(a: Tuple[float, ...], b: Tuple[float, ...]) -> Tuple[float, float, float, float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


class _RobotInterfaces:
    """The topics of one robot."""

    def __init__(self, node: SimNode, robot: Robot) -> None:
        import rospy
        from geometry_msgs.msg import Twist
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import JointState, LaserScan
        from std_msgs.msg import String

        self.node, self.robot = node, robot
        self.prefix = robot.name
        ns = robot.name + "/" if robot.name else ""
        self.Odometry, self.LaserScan, self.JointState = Odometry, LaserScan, JointState
        self.odom_pub = rospy.Publisher(ns + "odom", Odometry, queue_size=10)
        self.truth_pub = rospy.Publisher(ns + "base_pose_ground_truth", Odometry, queue_size=10)
        self.scan_pub = rospy.Publisher(ns + "scan", LaserScan, queue_size=10)
        self.joint_pub = rospy.Publisher(ns + "joint_states", JointState, queue_size=10)
        self.description_pub = rospy.Publisher(ns + "robot_description", String, queue_size=1,
                                               latch=True)
        self.description_pub.publish(String(data=node.description))
        rospy.set_param(ns + "robot_description", node.description)
        if self.prefix:
            rospy.set_param(ns + "tf_prefix", self.prefix)
        self.cmd_sub = rospy.Subscriber(ns + "cmd_vel", Twist, self._on_cmd_vel, queue_size=10)
        self.frames = {name: frame(self.prefix, name) for name in (
            "odom", "base_footprint", "base_link", "base_scan", "wheel_left_link",
            "wheel_right_link")}

    def _on_cmd_vel(self, msg: Any) -> None:
        import rospy

        try:
            with self.node.lock:
                self.node.world.command(self.robot.name, msg.linear.x, msg.angular.z)
        except WorldError as exc:
            topic = self.cmd_sub.resolved_name
            rospy.logwarn_throttle(5.0, f"{topic}: {exc}")

    def odometry(self, stamp: Any, transforms: List[Any]) -> None:
        from geometry_msgs.msg import TransformStamped

        r = self.robot
        ox, oy, oyaw = r.odometry()
        q = _quaternion(0.0, 0.0, oyaw)
        odom = self.Odometry()
        odom.header.stamp = stamp
        odom.header.frame_id = self.frames["odom"]
        odom.child_frame_id = self.frames["base_footprint"]
        pose = odom.pose.pose
        pose.position.x, pose.position.y = ox, oy
        pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = q
        odom.twist.twist.linear.x = r.actual_v
        odom.twist.twist.angular.z = r.actual_w
        self.odom_pub.publish(odom)

        truth = self.Odometry()
        truth.header.stamp = stamp
        truth.header.frame_id = "map"
        truth.child_frame_id = self.frames["base_footprint"]
        tq = _quaternion(0.0, 0.0, r.yaw)
        tp = truth.pose.pose
        tp.position.x, tp.position.y = r.x, r.y
        tp.orientation.x, tp.orientation.y, tp.orientation.z, tp.orientation.w = tq
        truth.twist.twist.linear.x = r.actual_v
        truth.twist.twist.angular.z = r.actual_w
        self.truth_pub.publish(truth)

        t = TransformStamped()
        t.header.stamp = stamp
        t.header.frame_id = self.frames["odom"]
        t.child_frame_id = self.frames["base_footprint"]
        t.transform.translation.x, t.transform.translation.y = ox, oy
        rot = t.transform.rotation
        rot.x, rot.y, rot.z, rot.w = q
        transforms.append(t)

        joints = self.JointState()
        joints.header.stamp = stamp
        joints.name = list(model.WHEELS)
        joints.position = [r.wheel_left, r.wheel_right]
        joints.velocity = list(kinematics.wheel_speeds(r.actual_v, r.actual_w))
        joints.effort = []
        self.joint_pub.publish(joints)
        for fixed, angle in zip(model.WHEELS.values(), (r.wheel_left, r.wheel_right)):
            w = TransformStamped()
            w.header.stamp = stamp
            w.header.frame_id = frame(self.prefix, fixed.parent)
            w.child_frame_id = frame(self.prefix, fixed.child)
            w.transform.translation.x, w.transform.translation.y, w.transform.translation.z = fixed.xyz
            wq = _multiply(_quaternion(*fixed.rpy), _quaternion(0.0, 0.0, angle))
            w.transform.rotation.x, w.transform.rotation.y, w.transform.rotation.z, \
                w.transform.rotation.w = wq
            transforms.append(w)

    def scan(self, stamp: Any, ranges: Any) -> None:
        laser = self.robot.laser
        msg = self.LaserScan()
        msg.header.stamp = stamp
        msg.header.frame_id = self.frames["base_scan"]
        msg.angle_min = laser.angle_min
        msg.angle_max = laser.angle_max
        msg.angle_increment = laser.increment
        msg.time_increment = 0.0
        msg.scan_time = self.node.scan_period
        msg.range_min = laser.range_min
        msg.range_max = laser.range_max
        msg.ranges = ranges
        msg.intensities = []
        self.scan_pub.publish(msg)

    def static_transforms(self, localization: bool) -> List[Any]:
        import rospy
        from geometry_msgs.msg import TransformStamped

        out = []
        r = self.robot
        if localization:
            t = TransformStamped()
            t.header.stamp = rospy.Time(0)
            t.header.frame_id = "map"
            t.child_frame_id = self.frames["odom"]
            sx, sy, syaw = r.start
            t.transform.translation.x, t.transform.translation.y = sx, sy
            q = _quaternion(0.0, 0.0, syaw)
            t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, \
                t.transform.rotation.w = q
            out.append(t)
        for fixed in model.FIXED_FRAMES:
            t = TransformStamped()
            t.header.frame_id = frame(self.prefix, fixed.parent)
            t.child_frame_id = frame(self.prefix, fixed.child)
            t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = fixed.xyz
            q = _quaternion(*fixed.rpy)
            t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, \
                t.transform.rotation.w = q
            out.append(t)
        return out


class SimNode:
    """The simulator node: a :class:`World`, its lock, and every robot's topics."""

    def __init__(self, world: World, args: argparse.Namespace) -> None:
        import rospy
        import tf2_ros
        from rosgraph_msgs.msg import Clock
        from sensor_msgs.msg import Image
        from std_srvs.srv import Empty

        self.world = world
        self.args = args
        self.lock = threading.Lock()
        self.description = model.urdf()
        self.scan_period = 1.0 / args.laser_rate
        self.Clock, self.Image = Clock, Image
        self.tf = tf2_ros.TransformBroadcaster()
        self.static_tf = tf2_ros.StaticTransformBroadcaster()
        self.robots = [_RobotInterfaces(self, r) for r in world.robots.values()]
        statics: List[Any] = []
        for iface in self.robots:
            statics += iface.static_transforms(not args.no_localization)
        self.static_tf.sendTransform(statics)
        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=10) if args.clock else None
        self.view_pub = rospy.Publisher("~view", Image, queue_size=1)
        self.reset_srv = rospy.Service("reset_positions", Empty, self._on_reset)
        self.renderer = None
        self.last_scans: Dict[str, Any] = {}
        self.stalled: Dict[str, bool] = {}

    def _on_reset(self, _req: Any) -> Any:
        with self.lock:
            self.world.reset()
        return []

    def stamp(self) -> Any:
        import rospy

        if self.clock_pub is not None:
            return rospy.Time.from_sec(self.world.time)
        return rospy.Time.now()

    def step(self, dt: float, scan: bool) -> None:
        """One tick: move, publish odometry and tf, and the scans when due."""
        import rospy

        with self.lock:
            self.world.step(dt)
            scans = self.world.scan() if scan else None
            bumped = [r for r in self.world.robots.values()
                      if r.stalled and not self.stalled.get(r.name)]
            self.stalled = {r.name: r.stalled for r in self.world.robots.values()}
        for robot in bumped:
            rospy.logwarn(f"Bump! {robot.name or 'The robot'} hit an obstacle at "
                          f"({robot.x:.2f}, {robot.y:.2f}) and stopped")
        stamp = self.stamp()
        if self.clock_pub is not None:
            self.clock_pub.publish(self.Clock(clock=stamp))
        transforms: List[Any] = []
        for iface in self.robots:
            iface.odometry(stamp, transforms)
        self.tf.sendTransform(transforms)
        if scans is not None:
            self.last_scans = scans
            for iface in self.robots:
                iface.scan(stamp, scans[iface.robot.name])

    def wants_view(self) -> bool:
        return self.view_pub.get_num_connections() > 0

    def render(self) -> Any:
        from minros.sim.render import Renderer

        with self.lock:
            if self.renderer is None:
                self.renderer = Renderer(self.world)
            return self.renderer.render(self.last_scans)

    def publish_view(self, image: Any) -> None:
        msg = self.Image()
        msg.header.stamp = self.stamp()
        msg.header.frame_id = "map"
        msg.height, msg.width = int(image.shape[0]), int(image.shape[1])
        msg.encoding = "bgr8"
        msg.step = msg.width * 3
        msg.data = image.tobytes()
        self.view_pub.publish(msg)


class _Window:
    """A Tk window showing the top-down view (``--window``), like turtlesim's."""

    def __init__(self, title: str) -> None:
        import tkinter

        self.tk = tkinter
        self.root = tkinter.Tk()
        self.root.title(title)
        self.closed = False
        self.root.protocol("WM_DELETE_WINDOW", self._close)
        self.label = tkinter.Label(self.root, borderwidth=0)
        self.label.pack()
        self.photo = None

    def _close(self) -> None:
        self.closed = True

    def show(self, bgr: Any) -> None:
        rgb = bgr[:, :, ::-1]
        header = b"P6 %d %d 255\n" % (rgb.shape[1], rgb.shape[0])
        self.photo = self.tk.PhotoImage(data=header + rgb.tobytes(), format="PPM")
        self.label.configure(image=self.photo)

    def pump(self) -> bool:
        self.root.update()
        return not self.closed

    def destroy(self) -> None:
        try:
            self.root.destroy()
        except Exception:  # the display went away first
            pass


def _open_window() -> Tuple[_Window | None, str]:
    if not os.environ.get("DISPLAY") and sys.platform.startswith("linux"):
        return None, "no DISPLAY"
    try:
        return _Window("minros sim"), ""
    except Exception as exc:  # no tkinter, or the display refused
        return None, (str(exc).splitlines() or [type(exc).__name__])[0]


def build_parser(prog: str = "sim_node") -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog, description="minros's 2D simulator: TurtleBot3 Burger-like robots with a "
                               "360-beam laser on a map_server map.")
    parser.add_argument("world", nargs="?", default=DEFAULT_WORLD,
                        help="map YAML file in map_server's format (default: minros's rooms)")
    parser.add_argument("--robots", type=int, default=None, metavar="N",
                        help="N robots in a row through (0, 0), named tb3_0... when N > 1 "
                             "(default 1, unnamed)")
    parser.add_argument("--robot", action="append", default=[], metavar="[NAME=]X,Y[,YAW]",
                        help="a robot at this pose in the map frame (repeat for more robots)")
    parser.add_argument("--rate", type=float, default=30.0, metavar="HZ",
                        help="simulation steps, odometry and tf per simulated second (default 30)")
    parser.add_argument("--laser-rate", type=float, default=10.0, metavar="HZ",
                        help="laser scans per simulated second (default 10)")
    parser.add_argument("--laser-noise", type=float, default=0.0, metavar="M",
                        help="standard deviation of range noise in metres (default 0)")
    parser.add_argument("--max-vel", default=f"{kinematics.MAX_LINEAR},{kinematics.MAX_ANGULAR}",
                        metavar="V,W", help="speed limits in m/s and rad/s (default: the "
                                            "TurtleBot3 Burger's 0.22,2.84)")
    parser.add_argument("--watchdog", type=float, default=0.5, metavar="S",
                        help="stop a robot that received no cmd_vel for S seconds "
                             "(default 0.5, as the TurtleBot3's firmware; 0 = never)")
    parser.add_argument("--no-localization", action="store_true",
                        help="do not publish map -> odom (run your own localization)")
    parser.add_argument("--clock", action="store_true",
                        help="publish /clock and stamp everything with simulated time")
    parser.add_argument("--speed", type=float, default=1.0, metavar="F",
                        help="simulated seconds per wall second (default 1; 0 = as fast as "
                             "possible; anything but 1 needs --clock)")
    parser.add_argument("--view-rate", type=float, default=10.0, metavar="HZ",
                        help="frames per wall second of the top-down view (default 10)")
    parser.add_argument("--window", action="store_true",
                        help="show the top-down view in a window (needs a display and tkinter)")
    parser.add_argument("--snapshot", metavar="FILE.png",
                        help="write the top-down view to FILE.png every second and at exit")
    return parser


def make_world(args: argparse.Namespace) -> World:
    """The world the arguments describe; MapError/WorldError/ValueError on bad input."""
    grid, _desc = mapfile.load_map(args.world)
    try:
        v_max, w_max = (float(v) for v in args.max_vel.split(","))
    except ValueError:
        raise ValueError(f"--max-vel {args.max_vel!r}: expected V,W (two numbers)") from None
    if not (v_max > 0 and w_max > 0):
        raise ValueError("--max-vel: both limits must be positive")
    limits = kinematics.Limits(v_max, w_max)
    world = World(grid, command_timeout=max(0.0, args.watchdog))
    poses = [parse_pose(p) for p in args.robot]
    count = args.robots if args.robots is not None else max(1, len(poses))
    if not 1 <= count <= 64:
        raise ValueError(f"--robots {count}: between 1 and 64 robots")
    if len(poses) > count:
        raise ValueError(f"{len(poses)} --robot poses for {count} robots")
    names = robot_names(count)
    laser = Laser(noise=max(0.0, args.laser_noise))
    for i, (name, x, y, yaw) in enumerate(poses):
        world.add_robot(Robot(_checked_name(names[i] if name is None else name), x, y, yaw,
                              limits=limits, laser=laser))
    candidates = row_candidates()
    for i in range(len(poses), count):
        for x, y in candidates:
            # a margin of 5 cm, so that robots do not start touching anything
            if not world.collides(x, y, Robot("", 0, 0, 0).radius + 0.05):
                world.add_robot(Robot(names[i], x, y, 0.0, limits=limits, laser=laser))
                break
        else:
            raise WorldError(f"no free place for robot {names[i] or 1} in a row through (0, 0): "
                             "place it with --robot X,Y,YAW")
    return world


def _checked_name(name: str) -> str:
    if name and not (name[0].isalpha() and all(c.isalnum() or c == "_" for c in name)):
        raise ValueError(f"robot name {name!r}: a letter, then letters, digits and _")
    return name


def main(argv: List[str] | None = None) -> int:
    import rospy

    full_argv = list(sys.argv if argv is None else argv)
    args = build_parser().parse_args(rospy.myargv(full_argv)[1:])
    for option, value in (("--rate", args.rate), ("--laser-rate", args.laser_rate),
                          ("--view-rate", args.view_rate)):
        if not (math.isfinite(value) and value > 0):
            sys.stderr.write(f"sim_node: {option} must be a positive number of Hz\n")
            return 2
    if not (math.isfinite(args.speed) and args.speed >= 0):
        sys.stderr.write("sim_node: --speed must be 0 (as fast as possible) or positive\n")
        return 2
    if args.speed != 1.0 and not args.clock:
        sys.stderr.write("sim_node: --speed other than 1 needs --clock (and /use_sim_time "
                         "true), or the nodes' clocks would disagree with the simulation\n")
        return 2
    try:
        world = make_world(args)
    except (mapfile.MapError, WorldError, ValueError) as exc:
        sys.stderr.write(f"sim_node: {exc}\n")
        return 1
    rospy.init_node("sim", argv=full_argv)
    node = SimNode(world, args)
    names = ", ".join(r.name or "robot" for r in world.robots.values())
    rospy.loginfo(f"minros sim: {len(world.robots)} robot(s) ({names}) on {args.world}, "
                  f"{args.rate:g} Hz steps, laser {args.laser_rate:g} Hz")
    window, reason = (_open_window() if args.window else (None, ""))
    if args.window and window is None:
        rospy.logwarn(f"minros sim runs without a window: {reason}")
    return _run(node, args, window)


def _run(node: SimNode, args: argparse.Namespace, window: _Window | None) -> int:
    import rospy

    dt = 1.0 / args.rate
    period = dt / args.speed if args.speed > 0 else 0.0
    steps_per_scan = max(1, round(args.rate / args.laser_rate))
    next_tick = time.monotonic()
    next_view = next_snapshot = next_tick
    tick = 0
    try:
        while not rospy.is_shutdown():
            try:
                node.step(dt, scan=tick % steps_per_scan == 0)
            except Exception as exc:  # a publisher closed by a shutdown racing this tick
                if rospy.is_shutdown():
                    break
                rospy.logerr_throttle(5.0, f"minros sim: step failed: {exc}")
            tick += 1
            now = time.monotonic()
            if now >= next_view and (window is not None or node.wants_view()):
                next_view = now + 1.0 / args.view_rate
                image = node.render()
                if node.wants_view():
                    node.publish_view(image)
                if window is not None:
                    window.show(image)
            if window is not None:
                try:
                    if not window.pump():
                        rospy.signal_shutdown("window closed")
                        break
                except Exception as exc:  # the display went away
                    rospy.logwarn(f"minros sim: window lost ({exc}); continuing without it")
                    window = None
            if args.snapshot and now >= next_snapshot:
                next_snapshot = now + 1.0
                _snapshot(node, args.snapshot)
            if period > 0:
                next_tick += period
                delay = next_tick - time.monotonic()
                if delay < -0.25:  # far behind (suspended, overloaded): do not burst
                    next_tick = time.monotonic()
                elif delay > 0:
                    time.sleep(delay)
    except KeyboardInterrupt:
        rospy.signal_shutdown("keyboard interrupt")
    finally:
        if args.snapshot:
            _snapshot(node, args.snapshot)
        if window is not None:
            window.destroy()
    return 0


def _snapshot(node: SimNode, path: str) -> None:
    from minros.nodes.turtlesim.turtlesim_node import write_snapshot

    try:
        write_snapshot(path, node.render()[:, :, ::-1])
    except Exception as exc:
        sys.stderr.write(f"sim_node: cannot write snapshot {path}: {exc}\n")


if __name__ == "__main__":
    from minros.nodes.turtlesim import run_tool

    sys.exit(run_tool("sim_node", main))
