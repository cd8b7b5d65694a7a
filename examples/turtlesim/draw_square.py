#!/usr/bin/env python3
"""Drive turtlesim's turtle around a square, closing the loop on /turtle1/pose.

    rosrun turtlesim turtlesim_node          (or: minros run turtlesim turtlesim_node --headless)
    python examples/turtlesim/draw_square.py [_side:=2.0] [_speed:=2.0]

Each side: drive forward until the pose says the side is done (slowing down near its end), then
turn left until the heading is 90 degrees further. Prints each corner and, at the end, how far
the turtle is from where it started.
"""

import math

import rospy
from geometry_msgs.msg import Twist
from turtlesim.msg import Pose


class Square:
    def __init__(self) -> None:
        self.pose = None
        self.side = float(rospy.get_param("~side", 2.0))
        self.speed = float(rospy.get_param("~speed", 2.0))
        self.cmd = rospy.Publisher("/turtle1/cmd_vel", Twist, queue_size=1)
        rospy.Subscriber("/turtle1/pose", Pose, self.on_pose)
        self.rate = rospy.Rate(100)

    def on_pose(self, msg: Pose) -> None:
        self.pose = msg

    def send(self, linear: float = 0.0, angular: float = 0.0) -> None:
        twist = Twist()
        twist.linear.x = linear
        twist.angular.z = angular
        self.cmd.publish(twist)
        self.rate.sleep()

    def forward(self, heading: float) -> None:
        x0, y0 = self.pose.x, self.pose.y
        while not rospy.is_shutdown():
            left = self.side - math.hypot(self.pose.x - x0, self.pose.y - y0)
            if left <= 0.005:
                break
            # slow down for the corner; steer back onto the side's heading
            self.send(min(self.speed, max(0.2, 8.0 * left)), 4.0 * angle(heading - self.pose.theta))
        self.send()

    def turn(self, heading: float) -> None:
        while not rospy.is_shutdown():
            error = angle(heading - self.pose.theta)
            if abs(error) <= 0.003:
                break
            turn = max(-2.0 * self.speed, min(2.0 * self.speed, 8.0 * error))
            self.send(0.0, math.copysign(max(0.1, abs(turn)), turn))
        self.send()

    def run(self) -> None:
        while self.pose is None and not rospy.is_shutdown():
            self.rate.sleep()
        start = self.pose
        heading = start.theta
        rospy.loginfo("start at (%.2f, %.2f), heading %.2f", start.x, start.y, heading)
        for corner in range(1, 5):
            self.forward(heading)
            heading = angle(heading + math.pi / 2)
            self.turn(heading)
            rospy.loginfo("corner %d at (%.2f, %.2f)", corner, self.pose.x, self.pose.y)
        gap = math.hypot(self.pose.x - start.x, self.pose.y - start.y)
        rospy.loginfo("square done: %.3f from the start", gap)


def angle(value: float) -> float:
    """``value`` in (-pi, pi]."""
    return math.atan2(math.sin(value), math.cos(value))


if __name__ == "__main__":
    rospy.init_node("draw_square")
    try:
        Square().run()
    except rospy.ROSInterruptException:
        pass
