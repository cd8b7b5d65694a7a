#!/usr/bin/env python3
"""Wander without hitting anything: the classic LaserScan obstacle-avoidance node.

    minros sim --no-nav                          # nobody else drives the robot
    python examples/sim/avoid_obstacles.py

Drive forward while the sector ahead is clear; when something is closer than SAFE metres,
turn towards the side with more room. It reads /scan and writes /cmd_vel, as a TurtleBot3
tutorial does, and runs unmodified under ROS's own rospy.
"""

import math

import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

SAFE = 0.5       # metres
SPEED = 0.2      # m/s
TURN = 1.0       # rad/s


def nearest(ranges):
    """The nearest valid reading (inf when nothing is in range; -inf means too close)."""
    return min([r for r in ranges if not math.isnan(r)] or [float("inf")])


class Avoider:
    def __init__(self):
        self.pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
        self.sub = rospy.Subscriber("scan", LaserScan, self.on_scan, queue_size=1)

    def on_scan(self, scan):
        ranges = list(scan.ranges)
        n = len(ranges)
        sector = n // 12  # 30 degrees on each side of straight ahead
        front = nearest(ranges[:sector] + ranges[n - sector:])
        left = nearest(ranges[sector:n // 4])
        right = nearest(ranges[3 * n // 4:n - sector])
        cmd = Twist()
        if front > SAFE:
            cmd.linear.x = SPEED
        else:
            cmd.angular.z = TURN if left >= right else -TURN
        self.pub.publish(cmd)

    def stop(self):
        self.pub.publish(Twist())


if __name__ == "__main__":
    rospy.init_node("avoid_obstacles")
    avoider = Avoider()
    rospy.on_shutdown(avoider.stop)
    rospy.spin()
