#!/usr/bin/env python3
"""A tf2 broadcaster: the frame ``moon`` circles the frame ``earth`` (radius 2 m, 0.5 rad/s).

    python examples/tf/broadcaster.py

Each transform goes out as a geometry_msgs/TransformStamped inside a tf2_msgs/TFMessage on /tf;
``rosrun tf tf_echo earth moon`` or examples/tf/listener.py read it back.
"""

import math

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped


def main() -> None:
    rospy.init_node("moon_broadcaster")
    broadcaster = tf2_ros.TransformBroadcaster()
    rate = rospy.Rate(20)
    while not rospy.is_shutdown():
        now = rospy.Time.now()
        angle = 0.5 * now.to_sec()
        t = TransformStamped()
        t.header.stamp = now
        t.header.frame_id = "earth"
        t.child_frame_id = "moon"
        t.transform.translation.x = 2.0 * math.cos(angle)
        t.transform.translation.y = 2.0 * math.sin(angle)
        # the moon always shows the earth the same face: it turns as it goes round
        t.transform.rotation.z = math.sin((angle + math.pi) / 2)
        t.transform.rotation.w = math.cos((angle + math.pi) / 2)
        broadcaster.sendTransform(t)
        rate.sleep()


if __name__ == "__main__":
    try:
        main()
    except rospy.ROSInterruptException:
        pass
