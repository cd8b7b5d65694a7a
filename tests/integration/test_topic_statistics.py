"""Topic statistics (/enable_statistics): a subscriber publishes rosgraph_msgs/TopicStatistics on
/statistics per connection, as rospy's does; off, it publishes nothing."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from xmlrpc.client import ServerProxy

import pytest

from support import PYTHON, REFERENCE_PYTHON, Proc, reference_env, require_reference, ros_env

PUBLISHER = '''
import rospy
from std_msgs.msg import Header
rospy.init_node("stat_pub")
pub = rospy.Publisher("/chatter", Header, queue_size=10)
rate = rospy.Rate(50)
seq = 0
while not rospy.is_shutdown():
    seq += 1
    pub.publish(Header(seq=seq, stamp=rospy.Time.now(), frame_id="f"))
    try:
        rate.sleep()
    except rospy.ROSInterruptException:
        break
'''

SUBSCRIBER = '''
import rospy
from std_msgs.msg import Header
rospy.init_node("stat_sub")
rospy.Subscriber("/chatter", Header, lambda m: None)
rospy.spin()
'''

READER = '''
import json, rospy
from rosgraph_msgs.msg import TopicStatistics
rospy.init_node("stat_reader", anonymous=True)
# the first window of a connection ends at its first message (rospy's rule too): read on to a
# window that had time to fill
for _ in range(10):
    m = rospy.wait_for_message("/statistics", TopicStatistics, timeout=20)
    if (m.window_stop - m.window_start).to_sec() >= 0.5:
        break
print(json.dumps({"topic": m.topic, "node_sub": m.node_sub, "node_pub": m.node_pub,
                  "delivered": m.delivered_msgs, "traffic": m.traffic,
                  "window": (m.window_stop - m.window_start).to_sec(),
                  "period_mean": m.period_mean.to_sec(), "age_max": m.stamp_age_max.to_sec()}))
'''


def _statistics(port: int, home: Path, subscriber_python: str, enable: bool) -> dict | None:
    env = ros_env(port, home)
    ServerProxy(f"http://localhost:{port}/").setParam("/test", "/enable_statistics", enable)
    pub = Proc([PYTHON, "-c", PUBLISHER], env)
    sub_env = env if subscriber_python == PYTHON else reference_env(env)
    sub = Proc([subscriber_python, "-c", SUBSCRIBER], sub_env)
    try:
        run = subprocess.run([PYTHON, "-c", READER], env=env, capture_output=True, text=True,
                             timeout=60)
        if run.returncode != 0:
            assert "timeout exceeded" in run.stderr, run.stderr
            return None
        return json.loads(run.stdout.strip().splitlines()[-1])
    finally:
        sub.stop()
        pub.stop()


def _check(stats: dict) -> None:
    assert (stats["topic"], stats["node_sub"], stats["node_pub"]) == ("/chatter", "/stat_sub", "/stat_pub")
    assert stats["delivered"] > 10
    assert stats["traffic"] > 0
    assert 0.5 < stats["window"] < 5
    assert 0.005 < stats["period_mean"] < 0.1
    assert 0 <= stats["age_max"] < 1


def test_minros_subscriber_publishes_statistics(minros_core: int, ros_home: Path) -> None:
    _check(_statistics(minros_core, ros_home, PYTHON, True))


@pytest.mark.timeout(90)
def test_statistics_off_publishes_nothing(minros_core: int, ros_home: Path) -> None:
    env = ros_env(minros_core, ros_home)
    pub = Proc([PYTHON, "-c", PUBLISHER], env)
    sub = Proc([PYTHON, "-c", SUBSCRIBER], env)
    try:
        master = ServerProxy(f"http://localhost:{minros_core}/")
        import time

        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:  # until the subscriber is connected and receiving
            subs = master.getSystemState("/test")[2][1]
            if any(t == "/chatter" and "/stat_sub" in n for t, n in subs):
                break
            time.sleep(0.1)
        time.sleep(1.5)  # longer than the first window: statistics would have been published
        pubs = master.getSystemState("/test")[2][0]
        assert not any(t == "/statistics" for t, _n in pubs)
    finally:
        sub.stop()
        pub.stop()


def test_rospy_subscriber_publishes_the_same_statistics(minros_core: int, ros_home: Path) -> None:
    require_reference()
    _check(_statistics(minros_core, ros_home, REFERENCE_PYTHON, True))
