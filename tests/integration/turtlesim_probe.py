"""Client side of the turtlesim integration tests, run as a separate minros node process.

``python turtlesim_probe.py COMMAND [args]`` prints one JSON line (``RESULT {...}``) and exits
0, or prints ``FAILED <reason>`` and exits 1. Every wait is bounded.
"""

from __future__ import annotations

import json
import sys
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from std_srvs.srv import Empty
from turtlesim.msg import Color, Pose
from turtlesim.srv import Kill, SetPen, Spawn, TeleportAbsolute

TIMEOUT = 10.0


class Latest:
    """The last message of a topic plus a count, with a bounded wait."""

    def __init__(self, topic: str, msg_class: type) -> None:
        self.cond = threading.Condition()
        self.msgs: list = []
        self.times: list = []
        self.sub = rospy.Subscriber(topic, msg_class, self._cb, queue_size=1000)

    def _cb(self, msg) -> None:
        with self.cond:
            self.msgs.append(msg)
            self.times.append(time.monotonic())
            self.cond.notify_all()

    def wait(self, pred=lambda msgs: bool(msgs), timeout: float = TIMEOUT):
        deadline = time.monotonic() + timeout
        with self.cond:
            while not pred(self.msgs):
                left = deadline - time.monotonic()
                if left <= 0:
                    fail(f"timed out waiting on {self.sub.name} ({len(self.msgs)} messages)")
                self.cond.wait(left)
            return self.msgs[-1]


def fail(reason: str) -> None:
    print("FAILED " + reason, flush=True)
    rospy.signal_shutdown("probe failed")
    sys.exit(1)


def pose_dict(p) -> dict:
    return {"x": p.x, "y": p.y, "theta": p.theta, "linear_velocity": p.linear_velocity,
            "angular_velocity": p.angular_velocity}


def cmd_drive(ns: str, hold: str = "0") -> dict:
    """Publish a Twist on <ns>/cmd_vel until <ns>/pose moves (then ``hold`` seconds more);
    report the poses before and while moving."""
    poses = Latest(f"{ns}/pose", Pose)
    first = poses.wait()
    pub = rospy.Publisher(f"{ns}/cmd_vel", Twist, queue_size=1)
    twist = Twist()
    twist.linear.x, twist.angular.z = 2.0, 1.0
    deadline = time.monotonic() + TIMEOUT
    while time.monotonic() < deadline:
        pub.publish(twist)
        last = poses.msgs[-1]
        if last.linear_velocity == 2.0 and last.x != first.x:
            break
        time.sleep(0.05)
    moving = poses.wait(lambda m: m[-1].linear_velocity == 2.0 and m[-1].x != first.x)
    end = time.monotonic() + float(hold)
    while time.monotonic() < end and not rospy.is_shutdown():
        pub.publish(twist)
        time.sleep(0.05)
    return {"first": pose_dict(first), "moving": pose_dict(moving)}


def cmd_rate(topic: str, seconds: str) -> dict:
    poses = Latest(topic, Pose)
    poses.wait()
    start = len(poses.msgs)
    t0 = poses.times[start - 1]
    time.sleep(float(seconds))
    with poses.cond:
        n = len(poses.msgs) - start
        t1 = poses.times[-1]
    return {"rate": n / (t1 - t0), "count": n}


def call_error(proxy, *args) -> str:
    try:
        proxy(*args)
    except rospy.ServiceException as exc:
        return str(exc)
    return ""


def cmd_services() -> dict:
    """spawn/kill/set_pen/teleport/clear through the services, and what the master shows."""
    for name in ("spawn", "kill", "clear", "turtle1/set_pen", "turtle1/teleport_absolute"):
        rospy.wait_for_service(name, TIMEOUT)
    spawn = rospy.ServiceProxy("spawn", Spawn)
    kill = rospy.ServiceProxy("kill", Kill)
    out: dict = {}
    out["spawned"] = spawn(3.0, 4.0, 0.5, "").name
    out["named"] = spawn(1.0, 1.0, 0.0, "leo").name
    poses = Latest("/leo/pose", Pose)
    out["leo_pose"] = pose_dict(poses.wait())
    out["duplicate_error"] = call_error(spawn, 1.0, 1.0, 0.0, "leo")
    out["illegal_error"] = call_error(spawn, 1.0, 1.0, 0.0, "no way")
    topics_before = sorted(t for t, _ in rospy.get_published_topics())
    kill("leo")
    deadline = time.monotonic() + TIMEOUT
    while "/leo/pose" in [t for t, _ in rospy.get_published_topics()]:
        if time.monotonic() > deadline:
            fail("/leo/pose still registered after kill")
        time.sleep(0.05)
    out["topics_before_kill"] = topics_before
    out["topics_after_kill"] = sorted(t for t, _ in rospy.get_published_topics())
    out["kill_unknown_error"] = call_error(kill, "leo")
    # set_pen + teleport: the colour sensor sees the new pen under the turtle.
    colors = Latest("/turtle1/color_sensor", Color)
    rospy.ServiceProxy("turtle1/set_pen", SetPen)(255, 0, 0, 4, 0)
    rospy.ServiceProxy("turtle1/teleport_absolute", TeleportAbsolute)(2.0, 2.0, 0.0)
    red = colors.wait(lambda m: bool(m) and (m[-1].r, m[-1].g, m[-1].b) == (255, 0, 0))
    out["color"] = [red.r, red.g, red.b]
    # NaN from a client: the service says why, the simulator keeps running with finite poses.
    out["nan_teleport_error"] = call_error(
        rospy.ServiceProxy("turtle1/teleport_absolute", TeleportAbsolute), float("nan"), 1.0, 0.0)
    bad = Twist()
    bad.angular.z = float("inf")
    cmd = rospy.Publisher("turtle1/cmd_vel", Twist, queue_size=1)
    poses = Latest("/turtle1/pose", Pose)
    for _ in range(10):
        cmd.publish(bad)
        time.sleep(0.02)
    poses.msgs.clear()
    after = poses.wait(lambda m: len(m) >= 5)
    out["pose_after_inf"] = pose_dict(after)
    rospy.set_param("/turtlesim/background_r", 10)
    rospy.ServiceProxy("clear", Empty)()
    colors.msgs.clear()
    back = colors.wait(lambda m: bool(m) and m[-1].r == 10)
    out["after_clear"] = [back.r, back.g, back.b]
    out["params"] = {k: rospy.get_param("/turtlesim/" + k) for k in ("background_r", "background_g", "background_b")}
    return out


def cmd_first_twist(topic: str) -> dict:
    """Wait for one Twist on ``topic`` (e.g. from teleop or mimic)."""
    twists = Latest(topic, Twist)
    print("READY", flush=True)
    msg = twists.wait(lambda m: any(t.linear.x or t.angular.z for t in m))
    return {"linear_x": msg.linear.x, "angular_z": msg.angular.z, "linear_y": msg.linear.y}


def cmd_wait_moving(topic: str, speed: str) -> dict:
    """Wait until a pose on ``topic`` reports linear_velocity == speed."""
    poses = Latest(topic, Pose)
    poses.wait()
    print("READY", flush=True)  # connected: the caller may start the motion now
    moving = poses.wait(lambda m: bool(m) and abs(m[-1].linear_velocity - float(speed)) < 1e-6)
    return {"pose": pose_dict(moving)}


def cmd_wait_pose(topic: str, field: str, value: str) -> dict:
    """Wait until a pose on ``topic`` has ``field`` == value (within 1e-6)."""
    poses = Latest(topic, Pose)
    pose = poses.wait(lambda m: bool(m) and abs(getattr(m[-1], field) - float(value)) < 1e-6)
    return {"pose": pose_dict(pose)}


def main() -> None:
    command, args = sys.argv[1], sys.argv[2:]
    rospy.init_node("turtlesim_probe", anonymous=True)
    handlers = {"drive": cmd_drive, "rate": cmd_rate, "services": cmd_services,
                "first_twist": cmd_first_twist, "wait_moving": cmd_wait_moving,
                "wait_pose": cmd_wait_pose}
    result = handlers[command](*args)
    print("RESULT " + json.dumps(result), flush=True)
    rospy.signal_shutdown("probe done")


if __name__ == "__main__":
    main()
