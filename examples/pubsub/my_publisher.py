#!/usr/bin/env python
# Seed 000 ("Publisher and Subscriber", step 4), as printed; scanning damage repaired only:
# "std msgs" -> std_msgs, "rospy. Publisher" -> rospy.Publisher, 'my topic' -> 'my_topic',
# "queue size" -> queue_size, "is shutdown" -> is_shutdown, the indentation and the
# "if__name__ == '__ main ':" line.
import rospy
from std_msgs.msg import String
def publisher():
    pub = rospy.Publisher('my_topic', String, queue_size=10)
    rospy.init_node('my_publisher', anonymous=True)
    rate = rospy.Rate(10) # 10hz
    while not rospy.is_shutdown():
        message = "Hello ROS!"
        rospy.loginfo(message)
        pub.publish(message)
        rate.sleep()
if __name__ == '__main__':
    try:
        publisher()
    except rospy.ROSInterruptException:
        pass
