"""talker.py: publishes "hello world <time>" on ``chatter`` (std_msgs/String) at 10 Hz."""

from __future__ import annotations

import rospy
from std_msgs.msg import String


def talker() -> None:
    pub = rospy.Publisher("chatter", String, queue_size=10)
    rospy.init_node("talker", anonymous=True)
    rate = rospy.Rate(10)
    while not rospy.is_shutdown():
        text = f"hello world {rospy.get_time()}"
        rospy.loginfo(text)
        pub.publish(text)
        rate.sleep()


if __name__ == "__main__":
    try:
        talker()
    except rospy.ROSInterruptException:
        pass
