#!/usr/bin/env python
# Seed 001 ("Writing Your First ROS Node"), subscriber.py exactly as printed.
import rospy
from std_msgs.msg import String

def callback(data):
    rospy.loginfo(rospy.get_caller_id() + "I heard %s", data.data)
    
def subscriber():
    rospy.init_node('subscriber', anonymous=True)
    rospy.Subscriber("my_topic", String, callback)
    rospy.spin()

if __name__ == '__main__':
    subscriber()
