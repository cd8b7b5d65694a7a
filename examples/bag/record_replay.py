#!/usr/bin/env python3
"""Record a topic into a bag, look inside it, play it back.

    python examples/bag/record_replay.py [--dir DIR]

Starts ``rosbag record -O chatter.bag /chatter``, publishes ten messages, stops the recorder
with Ctrl-C (SIGINT, as you would), prints ``rosbag info`` and the messages read back with the
rosbag Python API, then subscribes to /chatter and runs ``rosbag play``: the same ten messages
arrive again, from the bag. Needs a master (roscore or minros core).
"""

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time

import rosbag
import rospy
from std_msgs.msg import String

#: the rosbag command (minros's, run by this interpreter, so no PATH set-up is needed)
ROSBAG = [sys.executable, "-m", "minros", "bag"]


def wait_for_subscriber(pub, timeout: float = 15.0) -> None:
    deadline = time.monotonic() + timeout
    while pub.get_num_connections() == 0:
        if time.monotonic() > deadline:
            sys.exit("the recorder did not subscribe to /chatter")
        rospy.sleep(0.05)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dir", default=None, help="where to write chatter.bag (default: a temporary folder)")
    args = parser.parse_args(rospy.myargv()[1:])
    folder = args.dir or tempfile.mkdtemp(prefix="record_replay-")
    path = os.path.join(folder, "chatter.bag")
    rospy.init_node("record_replay")
    pub = rospy.Publisher("chatter", String, queue_size=10)

    print(f"== rosbag record -O {path} /chatter")
    recorder = subprocess.Popen([*ROSBAG, "record", "-O", path, "/chatter"])
    wait_for_subscriber(pub)
    for i in range(10):
        pub.publish(String(f"recorded {i}"))
        rospy.sleep(0.05)
    rospy.sleep(0.5)  # the recorder writes what it got, then we stop it as Ctrl-C would
    recorder.send_signal(signal.SIGINT)
    recorder.wait(15)

    print("== rosbag info")
    subprocess.run([*ROSBAG, "info", path], check=True)
    with rosbag.Bag(path) as bag:
        texts = [msg.data for _topic, msg, _t in bag.read_messages(topics=["/chatter"])]
    print(f"== read back: {texts}")

    replayed = []
    rospy.Subscriber("chatter", String, lambda msg: replayed.append(msg.data))
    pub.unregister()  # the bag is the publisher now
    print("== rosbag play")
    subprocess.run([*ROSBAG, "play", "--quiet", path], check=True)
    deadline = time.monotonic() + 5.0
    while len(replayed) < len(texts) and time.monotonic() < deadline:
        rospy.sleep(0.05)
    print(f"== replayed: {replayed}")


if __name__ == "__main__":
    main()
