#!/usr/bin/env python3
"""A node that prints its own wire trace: what it said to the master and to itself.

    python examples/trace/own_trace.py

It sets MINROS_TRACE before importing rospy (minros opens the trace when it is imported), then
publishes three messages to a subscriber in the same process, shuts down, and prints the
sequence with ``minros trace show``: registerPublisher, registerSubscriber, the master's
publisherUpdate, requestTopic, the TCP connection to itself, both connection headers and the
frames. Needs a master (roscore or minros core).
"""

import os
import sys
import tempfile
import threading

PATH = os.path.join(tempfile.mkdtemp(prefix="own_trace-"), "trace.jsonl")
os.environ["MINROS_TRACE"] = PATH  # before rospy: every minros process reads it on import
os.environ["MINROS_TRACE_MESSAGES"] = "1"  # and decode the frames

import rospy  # noqa: E402
from std_msgs.msg import String  # noqa: E402


def main() -> None:
    rospy.init_node("own_trace")
    heard = threading.Event()
    got = []

    def callback(msg: String) -> None:
        got.append(msg.data)
        if len(got) == 3:
            heard.set()

    rospy.Subscriber("echo", String, callback)
    pub = rospy.Publisher("echo", String, queue_size=10)
    while pub.get_num_connections() == 0 and not rospy.is_shutdown():
        rospy.sleep(0.01)
    for i in range(3):
        pub.publish(String(f"to myself {i}"))
    if not heard.wait(10):
        sys.exit("the messages did not come back")
    rospy.signal_shutdown("done")

    from minros.cli.trace import main as trace_main

    trace_main(["show", "--topic", "/echo", PATH])


if __name__ == "__main__":
    main()
