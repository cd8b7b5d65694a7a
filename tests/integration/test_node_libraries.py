"""actionlib and message_filters on minros alone, over real topics of a ``minros core``:
many quick goals each get exactly one active and one done callback (no transition lost to a
fast server), a finished goal leaves the status list after status_list_timeout, a
SimpleActionServer driven by goal and preempt callbacks, and
synchronizers fed by message_filters.Subscriber pair the messages of two topics."""

from __future__ import annotations

from pathlib import Path

import pytest

from support import PYTHON, Proc, ros_env

ACTIONS = r'''
import threading
import rospy
import actionlib
from actionlib.msg import TwoIntsAction, TwoIntsGoal, TwoIntsResult
from actionlib_msgs.msg import GoalStatusArray

rospy.init_node("actions")
rospy.set_param("/quick/status_list_timeout", 0.5)
server = actionlib.SimpleActionServer(
    "quick", TwoIntsAction,
    lambda goal: server.set_succeeded(TwoIntsResult(sum=goal.a + goal.b)), auto_start=False)
server.start()
client = actionlib.SimpleActionClient("quick", TwoIntsAction)
print("server", client.wait_for_server(rospy.Duration(20)), flush=True)
counts = {"active": 0, "done": 0, "sum": 0}
for i in range(30):
    client.send_goal(TwoIntsGoal(a=i, b=1), active_cb=lambda: counts.__setitem__("active", counts["active"] + 1),
                     done_cb=lambda s, r: counts.__setitem__("done", counts["done"] + 1))
    client.wait_for_result(rospy.Duration(10))
    counts["sum"] += client.get_result().sum
print("goals", counts["active"], counts["done"], counts["sum"], flush=True)
last = client.gh.comm_state_machine.action_goal.goal_id.id
# the server stamped the last result when it finished the goal: its 0.5 s runs from there (the
# client's own clock would start late on a loaded machine, when the result took a while to arrive)
done_at = client.gh.comm_state_machine.latest_result.header.stamp.to_sec()
gone = threading.Event()
gone_at = []
def on_status(msg):
    # server times throughout; status lists published before the result (still on their way
    # through the client's own status subscription, which this one shares) do not count
    stamp = msg.header.stamp.to_sec()
    if stamp >= done_at and all(s.goal_id.id != last for s in msg.status_list) and not gone.is_set():
        gone_at.append(stamp)
        gone.set()
rospy.Subscriber("quick/status", GoalStatusArray, on_status)
# forgotten after the 0.5 s set above, not at once nor at actionlib's default 5 s (slack for a
# busy machine), counted from the result, not from when this subscriber came up
forgotten = gone.wait(10)
print(f"[forgotten after {gone_at[0] - done_at if gone_at else None} s]", flush=True)
print("forgotten", forgotten, bool(gone_at) and 0.4 < gone_at[0] - done_at < 4.5, flush=True)

# goal and preempt callbacks instead of an execute callback
polled = actionlib.SimpleActionServer("polled", TwoIntsAction, auto_start=False)
preempts = []


def on_goal():
    goal = polled.accept_new_goal()
    if goal.a:
        polled.set_succeeded(TwoIntsResult(sum=goal.a * 10), "at once")


def on_preempt():
    preempts.append(polled.is_preempt_requested())
    polled.set_preempted(TwoIntsResult(sum=-5), "stopped")


polled.register_goal_callback(on_goal)
polled.register_preempt_callback(on_preempt)
polled.start()
other = actionlib.SimpleActionClient("polled", TwoIntsAction)
other.wait_for_server(rospy.Duration(20))
other.send_goal(TwoIntsGoal(a=4))
other.wait_for_result(rospy.Duration(10))
first = (actionlib.GoalStatus.to_string(other.get_state()), other.get_result().sum)
other.send_goal(TwoIntsGoal(a=0))
deadline = rospy.get_time() + 10
while other.get_state() != actionlib.GoalStatus.ACTIVE and rospy.get_time() < deadline:
    rospy.sleep(0.01)
other.cancel_goal()
other.wait_for_result(rospy.Duration(10))
print("polled", first, actionlib.GoalStatus.to_string(other.get_state()), other.get_result().sum,
      other.get_goal_status_text(), preempts, flush=True)
'''

FILTERS = r'''
import threading
import rospy
import message_filters
from geometry_msgs.msg import PointStamped

rospy.init_node("filters")
left_pub = rospy.Publisher("left", PointStamped, queue_size=100)
right_pub = rospy.Publisher("right", PointStamped, queue_size=100)
left = message_filters.Subscriber("left", PointStamped)
right = message_filters.Subscriber("right", PointStamped)
cache = message_filters.Cache(left, 5)
exact, approx = [], []
enough = threading.Event()
def on_exact(l, r):
    exact.append((l.point.x, r.point.x))
def on_approx(l, r):
    approx.append((l.point.x, r.point.x))
    if len(approx) == 20:
        enough.set()
message_filters.TimeSynchronizer([left, right], 10).registerCallback(on_exact)
message_filters.ApproximateTimeSynchronizer([left, right], 10, 0.01).registerCallback(on_approx)
while left_pub.get_num_connections() < 1 or right_pub.get_num_connections() < 1:
    rospy.sleep(0.02)
base = rospy.Time(50)
for i in range(20):
    a, b = PointStamped(), PointStamped()
    a.header.stamp = base + rospy.Duration(0, 100000000 * i)
    b.header.stamp = a.header.stamp + rospy.Duration(0, 3000000 * (i % 2))  # every other 3 ms late
    a.point.x = b.point.x = i
    left_pub.publish(a)
    right_pub.publish(b)
    rospy.sleep(0.01)
print("synced", enough.wait(10), len(exact), sorted(approx) == [(i, i) for i in range(20)],
      sorted(exact) == [(i, i) for i in range(0, 20, 2)], len(cache.cache_msgs), flush=True)
print("topic", left.getTopic(), left.get_num_connections(), flush=True)
'''


def _run(tmp_path: Path, port: int, home: Path, name: str, text: str, last: str) -> str:
    script = tmp_path / f"{name}.py"
    script.write_text(text)
    proc = Proc([PYTHON, str(script)], ros_env(port, home))
    try:
        return proc.read_until(last, 60)
    finally:
        proc.stop()


@pytest.mark.smoke
def test_many_quick_goals_and_status_list_timeout(tmp_path: Path, minros_core: int, ros_home: Path):
    out = _run(tmp_path, minros_core, ros_home, "actions", ACTIONS, "polled")
    lines = [line for line in out.splitlines() if not line.startswith("[")]
    assert lines == ["server True", "goals 30 30 465", "forgotten True True",
                     "polled ('SUCCEEDED', 40) PREEMPTED -5 stopped [True]"], out


@pytest.mark.smoke
def test_synchronizers_on_subscriber_filters(tmp_path: Path, minros_core: int, ros_home: Path):
    out = _run(tmp_path, minros_core, ros_home, "filters", FILTERS, "topic")
    lines = [line for line in out.splitlines() if not line.startswith("[")]
    assert lines == ["synced True 10 True True 5", "topic left 1"], out
