#!/usr/bin/env python3
"""The listener: prints what arrives on /chatter.

    python examples/talker_listener/listener.py [--count N]

Start it before or after the talker: the master tells it where /chatter is published either in
its answer to registerSubscriber (talker first) or with a publisherUpdate call (listener first).
"""

import argparse

import rospy
from std_msgs.msg import String


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=0, help="exit after N messages (0: never)")
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("listener")
    heard = []

    def callback(msg: String) -> None:
        heard.append(msg.data)
        rospy.loginfo("I heard %s", msg.data)
        if args.count and len(heard) >= args.count:
            rospy.signal_shutdown(f"heard {args.count} messages")

    rospy.Subscriber("chatter", String, callback)
    rospy.spin()


if __name__ == "__main__":
    main()
