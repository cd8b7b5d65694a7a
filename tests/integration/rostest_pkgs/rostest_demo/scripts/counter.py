#!/usr/bin/env python
"""A rospy node under test: counts up on ~out (std_msgs/Int32) from ~start, serves ~add."""
import rospy
from std_msgs.msg import Int32

rospy.init_node("counter")
start = rospy.get_param("~start", 0)
pub = rospy.Publisher("~out", Int32, queue_size=10)
rate = rospy.Rate(20)
n = start
while not rospy.is_shutdown():
    pub.publish(Int32(n))
    n += 1
    try:
        rate.sleep()
    except rospy.ROSInterruptException:
        break
