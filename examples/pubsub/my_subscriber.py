#!/usr/bin/env python
# Seed 000 ("Publisher and Subscriber", step 6), as printed; only the indentation of the
# try/except block (lost in scanning) is repaired.
import rospy
from std_msgs.msg import String
def callback(data):
    rospy.loginfo(rospy.get_caller_id() + "I heard %s", data.data)
def subscriber():
    rospy.init_node('my_subscriber', anonymous=True)
    rospy.Subscriber("my_topic", String, callback)
    rospy.spin()
if __name__ == '__main__':
    try:
        subscriber()
    except rospy.ROSInterruptException:
        pass
