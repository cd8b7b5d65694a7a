"""``rosrun turtlesim draw_square``: reset the simulator and drive turtle1 round a 2 m square.

As draw_square.cpp: node ``draw_square``; calls ``reset``, then a 16 ms wall timer runs a state
machine on the latest ``turtle1/pose``: FORWARD at 1.0 m/s until 2 m ahead (position tolerance
0.1, heading 0.01), STOP_FORWARD until the pose reports zero velocity, TURN at 0.4 rad/s by pi/2,
STOP_TURN, and again. Goals are logged as ``New goal [x y, theta]``.
"""

from __future__ import annotations

import math
import sys
import threading
from typing import Any, Callable, List, Tuple

#: draw_square.cpp's ``#define PI 3.141592``.
PI = 3.141592

FORWARD, STOP_FORWARD, TURN, STOP_TURN = "FORWARD", "STOP_FORWARD", "TURN", "STOP_TURN"


class SquareDriver:
    """The timer callback's state machine, without ROS: ``step(pose)`` -> Twist (lin, ang) or None.

    ``log`` receives the ROS_INFO lines. ``pose`` needs x, y, theta, linear_velocity,
    angular_velocity (turtlesim/Pose or anything alike).
    """

    def __init__(self, log: Callable[[str], None] = lambda text: None) -> None:
        self.log = log
        self.state = FORWARD
        self.goal: Tuple[float, float, float] | None = None

    def _set_goal(self, x: float, y: float, theta: float) -> None:
        self.goal = (x, y, theta)
        self.log(f"New goal [{x:f} {y:f}, {theta:f}]")

    def _reached(self, pose: Any) -> bool:
        gx, gy, gt = self.goal
        return abs(pose.x - gx) < 0.1 and abs(pose.y - gy) < 0.1 and abs(pose.theta - gt) < 0.01

    @staticmethod
    def _stopped(pose: Any) -> bool:
        return pose.angular_velocity < 0.0001 and pose.linear_velocity < 0.0001

    def _goal_ahead(self, pose: Any) -> None:
        self._set_goal(math.cos(pose.theta) * 2 + pose.x, math.sin(pose.theta) * 2 + pose.y, pose.theta)

    def step(self, pose: Any) -> Tuple[float, float] | None:
        if pose is None:
            return None
        if self.goal is None:
            self.state = FORWARD
            self._goal_ahead(pose)
        if self.state == FORWARD:
            if self._reached(pose):
                self.state = STOP_FORWARD
                return 0.0, 0.0
            return 1.0, 0.0
        if self.state == STOP_FORWARD:
            if self._stopped(pose):
                self.log("Reached goal")
                self.state = TURN
                theta = math.fmod(pose.theta + PI / 2.0, 2 * PI)
                if theta >= PI:  # keep the goal heading comparable with the pose's [-pi, pi)
                    theta -= 2 * PI
                self._set_goal(pose.x, pose.y, theta)
                return None
            return 0.0, 0.0
        if self.state == TURN:
            if self._reached(pose):
                self.state = STOP_TURN
                return 0.0, 0.0
            return 0.0, 0.4
        # STOP_TURN
        if self._stopped(pose):
            self.log("Reached goal")
            self.state = FORWARD
            self._goal_ahead(pose)
            return None
        return 0.0, 0.0


def main(argv: List[str] | None = None) -> int:
    import rospy
    from geometry_msgs.msg import Twist
    from std_srvs.srv import Empty
    from turtlesim.msg import Pose

    full_argv = list(sys.argv if argv is None else argv)
    rospy.init_node("draw_square", argv=full_argv)
    latest: List[Any] = [None]
    lock = threading.Lock()

    def on_pose(pose: Any) -> None:
        with lock:
            latest[0] = pose

    rospy.Subscriber("turtle1/pose", Pose, on_pose, queue_size=1)
    pub = rospy.Publisher("turtle1/cmd_vel", Twist, queue_size=1)
    reset = rospy.ServiceProxy("reset", Empty)
    try:
        reset()
    except Exception as exc:  # the C++ tool ignores the call's result too; say why, keep going
        rospy.logwarn(f"draw_square: calling reset failed: {exc}")
        if rospy.is_shutdown():
            return 0
    with lock:
        latest[0] = None  # poses from before the reset are stale
    driver = SquareDriver(log=rospy.loginfo)

    # createWallTimer(0.016): wall time, so it also runs when /use_sim_time has no /clock.
    from minros import node as _node

    while not rospy.is_shutdown():
        with lock:
            pose = latest[0]
        command = driver.step(pose)
        if command is not None:
            twist = Twist()
            twist.linear.x, twist.angular.z = command
            pub.publish(twist)
        _node.wait_for_shutdown(0.016)
    return 0


if __name__ == "__main__":
    from minros.nodes.turtlesim import run_tool

    sys.exit(run_tool("draw_square", main))
