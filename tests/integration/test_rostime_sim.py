"""Simulated time: with /use_sim_time true a node's clock follows /clock (0 until the first
message), and rospy.sleep / Rate / Timer wait for simulated, not wall, time."""

from __future__ import annotations

import xmlrpc.client
from pathlib import Path

import pytest

from support import PYTHON, Proc, ros_env

#: publishes /clock from 100 s upwards, 0.2 s of simulated time every 10 ms of wall time
#: (20x faster than real time); started only after the node has read time 0
CLOCK = r'''
import time
import rospy
from rosgraph_msgs.msg import Clock
rospy.init_node("clock_source", disable_rostime=True)
pub = rospy.Publisher("/clock", Clock, queue_size=10)
t = rospy.Time(100)
while not rospy.is_shutdown():
    pub.publish(Clock(clock=t))
    t = t + rospy.Duration(0, 200000000)
    time.sleep(0.01)
'''

NODE = r'''
import time
import rospy
rospy.init_node("sim_user")
print("T0 %r NOW_IS_TIME %s" % (rospy.get_time(), isinstance(rospy.Time.now(), rospy.Time)),
      flush=True)
while rospy.get_time() == 0 and not rospy.is_shutdown():
    time.sleep(0.01)
start_sim, start_wall = rospy.get_time(), time.monotonic()
rospy.sleep(2.0)
print("SLEPT sim=%.3f wall=%.3f" % (rospy.get_time() - start_sim, time.monotonic() - start_wall), flush=True)
rate = rospy.Rate(2)  # 0.5 s of simulated time per cycle
start_sim, start_wall = rospy.get_time(), time.monotonic()
for _ in range(4):
    rate.sleep()
print("RATE sim=%.3f wall=%.3f" % (rospy.get_time() - start_sim, time.monotonic() - start_wall), flush=True)
events = []
timer = rospy.Timer(rospy.Duration(1), events.append)
while len(events) < 2 and not rospy.is_shutdown():
    time.sleep(0.01)
timer.shutdown()
e = events[1]
print("TIMER expected_step=%.3f late=%s" % ((e.current_expected - e.last_expected).to_sec(),
      (e.current_real >= e.current_expected)), flush=True)
rospy.loginfo("sim log line")
print("DONE", flush=True)
rospy.spin()
'''


def value(line: str, key: str) -> float:
    return float(line.split(f"{key}=")[1].split()[0])


@pytest.mark.smoke
def test_node_follows_clock_topic(minros_master: int, ros_home: Path, tmp_path: Path):
    env = ros_env(minros_master, ros_home)
    master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
    assert master.setParam("/test", "/use_sim_time", True)[0] == 1
    node_script, clock_script = tmp_path / "node.py", tmp_path / "clock.py"
    node_script.write_text(NODE)
    clock_script.write_text(CLOCK)
    node = Proc([PYTHON, str(node_script)], env)
    clock = None
    try:
        out = node.read_until("NOW_IS_TIME", 30)
        assert "T0 0.0 NOW_IS_TIME True" in out  # no /clock message yet: simulated time is 0
        clock = Proc([PYTHON, str(clock_script)], env)
        slept = node.read_until("SLEPT", 30).splitlines()[-1]
        # 2 s of simulated time pass in about 0.1 s of wall time
        assert 2.0 <= value(slept, "sim") <= 2.6
        assert value(slept, "wall") < 1.5
        rate = node.read_until("RATE", 30).splitlines()[-1]
        assert 1.8 <= value(rate, "sim") <= 2.6 and value(rate, "wall") < 1.5
        # (TIMER, the log line and DONE come in one burst: read them in one go)
        out = node.read_until("DONE", 30)
        timer = next(x for x in out.splitlines() if x.startswith("TIMER"))
        assert value(timer, "expected_step") == pytest.approx(1.0)
        assert "late=True" in timer
        # the console shows wall time and, after a comma, the simulated time
        line = next(x for x in out.splitlines() if "sim log line" in x)
        stamp = line.split("] [", 1)[1].split("]", 1)[0]
        wall, sim = (float(x) for x in stamp.split(", "))
        assert wall > 1e9 and 100 <= sim < 1000
    finally:
        node.stop()
        if clock is not None:
            clock.stop()
