"""listener.py: logs every std_msgs/String received on ``chatter``."""

from __future__ import annotations

import rospy
from std_msgs.msg import String


def on_chatter(msg: String) -> None:
    rospy.loginfo(rospy.get_caller_id() + "I heard %s", msg.data)


def listener() -> None:
    # anonymous: several listeners may run side by side
    rospy.init_node("listener", anonymous=True)
    rospy.Subscriber("chatter", String, on_chatter)
    rospy.spin()


if __name__ == "__main__":
    listener()
