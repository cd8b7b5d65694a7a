"""The seed tutorials' publisher/subscriber scripts, run unmodified as a user would."""

from __future__ import annotations

import re

import pytest

from support import EXAMPLES, PYTHON, Proc, ros_env

SEED_DIR = EXAMPLES / "pubsub"
LOG_LINE = r"\[INFO\] \[\d+\.\d+\]: "


@pytest.mark.smoke
@pytest.mark.parametrize("publisher, subscriber, pub_text, sub_name", [
    # seed 001: "hello world <rospy.get_time()>"
    ("publisher.py", "subscriber.py", r"hello world \d+\.\d+", "subscriber"),
    # seed 000: "Hello ROS!"
    ("my_publisher.py", "my_subscriber.py", r"Hello ROS!", "my_subscriber"),
])
def test_seed_publisher_and_subscriber(minros_core, ros_home, publisher, subscriber, pub_text, sub_name):
    env = ros_env(minros_core, ros_home)
    pub = Proc([PYTHON, str(SEED_DIR / publisher)], env)
    sub = Proc([PYTHON, str(SEED_DIR / subscriber)], env)
    try:
        pub_out = pub.read_until("]: ", 20)
        sub_out = sub.read_until("I heard", 20)
        sub_out += sub.read_until("I heard", 5)  # and it keeps hearing at 10 Hz
    finally:
        sub_log = sub.stop()
        pub_log = pub.stop()
    # publisher: rospy.loginfo(message) -> "[INFO] [<wall time>]: <message>"
    assert re.search(LOG_LINE + pub_text + "$", pub_out, re.M), pub_out
    # subscriber: rospy.get_caller_id() + "I heard %s" -> "/<name>_<pid>_<millis>I heard <message>"
    heard = re.findall(LOG_LINE + rf"/{sub_name}_\d+_\d+I heard ({pub_text})$", sub_out, re.M)
    assert len(heard) >= 2, sub_out
    # Ctrl-C (SIGINT) ends both quietly: no traceback, as with rospy
    assert "Traceback" not in sub_log + pub_log
