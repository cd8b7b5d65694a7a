#!/usr/bin/env python3
"""The talker: publishes "hello world N" on /chatter, ten times a second.

    python examples/talker_listener/talker.py [--count N] [--wait] [_rate:=10]

Run it under ``minros trace -o talker.jsonl -- python ...`` to watch it register with the master,
answer the listener's requestTopic and send each message as a length-prefixed frame.
"""

import argparse

import rospy
from std_msgs.msg import String


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=0, help="stop after N messages (0: never)")
    parser.add_argument("--wait", action="store_true",
                        help="wait for a subscriber before the first message (messages published "
                             "before a subscriber connects go nowhere)")
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("talker")
    pub = rospy.Publisher("chatter", String, queue_size=10)
    rate = rospy.Rate(rospy.get_param("~rate", 10))
    while args.wait and pub.get_num_connections() == 0 and not rospy.is_shutdown():
        rospy.sleep(0.01)
    sent = 0
    while not rospy.is_shutdown() and (not args.count or sent < args.count):
        text = f"hello world {sent}"
        rospy.loginfo(text)
        pub.publish(text)
        sent += 1
        rate.sleep()


if __name__ == "__main__":
    try:
        main()
    except rospy.ROSInterruptException:
        pass
