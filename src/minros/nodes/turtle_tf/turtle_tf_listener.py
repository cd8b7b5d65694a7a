"""turtle_tf_listener.py: spawn turtle2 and steer it towards turtle1, reading turtle1's
position in turtle2's frame from tf (tf1 API, as the tutorial)."""

from __future__ import annotations

import math
import sys

import geometry_msgs.msg
import rospy
import tf
import turtlesim.srv


def main() -> int:
    rospy.init_node("turtle_tf_listener")
    listener = tf.TransformListener()
    rospy.wait_for_service("spawn")
    spawner = rospy.ServiceProxy("spawn", turtlesim.srv.Spawn)
    spawner(4, 2, 0, "turtle2")
    turtle_vel = rospy.Publisher("turtle2/cmd_vel", geometry_msgs.msg.Twist, queue_size=1)
    rate = rospy.Rate(10.0)
    while not rospy.is_shutdown():
        try:
            (trans, rot) = listener.lookupTransform("/turtle2", "/turtle1", rospy.Time())
        except (tf.LookupException, tf.ConnectivityException, tf.ExtrapolationException):
            continue  # the tutorial retries at once, until both turtles are in the tree
        msg = geometry_msgs.msg.Twist()
        msg.linear.x = 0.5 * math.sqrt(trans[0] ** 2 + trans[1] ** 2)
        msg.angular.z = 4 * math.atan2(trans[1], trans[0])
        turtle_vel.publish(msg)
        rate.sleep()
    return 0


if __name__ == "__main__":
    from minros.tf.tools import run_tool

    sys.exit(run_tool("turtle_tf_listener.py", main))
