"""Action server and client scripts that run unchanged on ROS 1's rospy+actionlib and on minros.

SERVER offers ``/simple`` (SimpleActionServer, execute callback: ``goal.a`` feedback steps of
0.1 s, result ``a + b``) and ``/handles`` (ActionServer with goal handles: rejects a < 0,
leaves a == 99 pending, accepts and succeeds the rest; cancel requests are granted).
CLIENT drives both and prints one line per check.
"""

SERVER = r'''
import threading
import rospy
import actionlib
from actionlib.msg import TwoIntsAction, TwoIntsFeedback, TwoIntsResult

rospy.init_node("two_ints_server")


def execute(goal):
    for _ in range(goal.a):
        if simple.is_preempt_requested():
            simple.set_preempted(TwoIntsResult(sum=-1), "preempted")
            return
        simple.publish_feedback(TwoIntsFeedback())
        rospy.sleep(0.1)
    simple.set_succeeded(TwoIntsResult(sum=goal.a + goal.b), "done")


simple = actionlib.SimpleActionServer("simple", TwoIntsAction, execute, auto_start=False)
simple.start()
pending = []


def on_goal(gh):
    goal = gh.get_goal()
    if goal.a < 0:
        gh.set_rejected(TwoIntsResult(sum=goal.a), "negative")
    elif goal.a == 99:
        pending.append(gh)
    else:
        gh.set_accepted("ok")
        gh.set_succeeded(TwoIntsResult(sum=goal.a + goal.b), "handled")


def on_cancel(gh):
    gh.set_canceled(TwoIntsResult(sum=-99), "recalled by request")


handles = actionlib.ActionServer("handles", TwoIntsAction, on_goal, on_cancel, auto_start=False)
handles.start()
print("server ready", flush=True)
rospy.spin()
'''

CLIENT = r'''
import threading
import time
import rospy
import actionlib
from actionlib_msgs.msg import GoalStatus, GoalStatusArray
from actionlib.msg import TwoIntsAction, TwoIntsGoal

NAMES = {v: k for k, v in vars(GoalStatus).items() if k.isupper() and isinstance(v, int)}
rospy.init_node("two_ints_client")


def say(*words):
    print(*words, flush=True)


client = actionlib.SimpleActionClient("simple", TwoIntsAction)
say("simple server", client.wait_for_server(rospy.Duration(20)))

# goal, feedback, result
feedback = []
done = []
client.send_goal(TwoIntsGoal(a=3, b=4), done_cb=lambda s, r: done.append((s, r.sum)),
                 feedback_cb=feedback.append)
client.wait_for_result(rospy.Duration(20))
say("goal1", NAMES[client.get_state()], "sum=%d" % client.get_result().sum,
    "feedback=%d" % len(feedback), "done_cb=%s" % (done == [(3, 7)]),
    "text=" + client.get_goal_status_text())

# preemption by a cancel request, once the client has seen the goal active (a status sent
# before the server had the goal could otherwise still be on its way, and mark it lost).
# Polled: ROS 1's SimpleActionClient can miss the ACTIVE callback when the server answers
# before send_goal has stored the goal handle.
first = threading.Event()
client.send_goal(TwoIntsGoal(a=50, b=1), feedback_cb=lambda fb: first.set())
deadline = time.monotonic() + 20
while client.gh.get_comm_state() != actionlib.CommState.ACTIVE and time.monotonic() < deadline:
    time.sleep(0.01)
say("goal2 feedback", first.wait(20), actionlib.CommState.to_string(client.gh.get_comm_state()))
client.cancel_goal()
client.wait_for_result(rospy.Duration(20))
say("goal2", NAMES[client.get_state()], "sum=%d" % client.get_result().sum,
    "text=" + client.get_goal_status_text())

# cancel of a finished goal: nothing changes, on either side
client.send_goal(TwoIntsGoal(a=1, b=1))
client.wait_for_result(rospy.Duration(20))
goal_id = client.gh.comm_state_machine.action_goal.goal_id.id
seen = []
cond = threading.Condition()


def on_status(msg):
    with cond:
        seen.append([s.status for s in msg.status_list if s.goal_id.id == goal_id])
        cond.notify_all()


status_sub = rospy.Subscriber("simple/status", GoalStatusArray, on_status)
client.cancel_goal()
with cond:
    cond.wait_for(lambda: len(seen) >= 3, 20)
say("goal3 after cancel", NAMES[client.get_state()], "sum=%d" % client.get_result().sum,
    "server says", sorted({NAMES[s] for statuses in seen[1:] for s in statuses}))
status_sub.unregister()

# a newer goal preempts the running one (SimpleActionServer's policy)
raw = actionlib.ActionClient("simple", TwoIntsAction)
raw.wait_for_server(rospy.Duration(20))
changed = threading.Condition()


def transition(gh):
    with changed:
        changed.notify_all()


old = raw.send_goal(TwoIntsGoal(a=50, b=0), transition_cb=transition)
with changed:
    changed.wait_for(lambda: old.get_comm_state() == actionlib.CommState.ACTIVE, 20)
new = raw.send_goal(TwoIntsGoal(a=1, b=2), transition_cb=transition)
with changed:
    changed.wait_for(lambda: old.get_comm_state() == actionlib.CommState.DONE
                     and new.get_comm_state() == actionlib.CommState.DONE, 20)
say("older goal", NAMES[old.get_terminal_state()], old.get_goal_status_text())
say("newer goal", NAMES[new.get_terminal_state()], "sum=%d" % new.get_result().sum)

# goal handles: rejected, accepted, recalled while pending
handles = actionlib.ActionClient("handles", TwoIntsAction)
say("handles server", handles.wait_for_server(rospy.Duration(20)))
for a in (-1, 5):
    gh = handles.send_goal(TwoIntsGoal(a=a, b=10), transition_cb=transition)
    with changed:
        changed.wait_for(lambda: gh.get_comm_state() == actionlib.CommState.DONE, 20)
    say("handle goal a=%d" % a, NAMES[gh.get_terminal_state()], gh.get_goal_status_text(),
        "sum=%d" % gh.get_result().sum)
gh = handles.send_goal(TwoIntsGoal(a=99, b=0), transition_cb=transition)
with changed:
    changed.wait_for(lambda: gh.get_comm_state() == actionlib.CommState.PENDING, 20)
gh.cancel()
with changed:
    changed.wait_for(lambda: gh.get_comm_state() == actionlib.CommState.DONE, 20)
say("pending goal cancelled", NAMES[gh.get_terminal_state()], gh.get_goal_status_text(),
    "sum=%d" % gh.get_result().sum)

# a cancel that overtakes its goal: the server remembers it and recalls the goal on arrival,
# without calling the user's goal callback
from actionlib_msgs.msg import GoalID
from actionlib.msg import TwoIntsActionGoal, TwoIntsActionResult

early = []
news = threading.Condition()


def on_result(msg):
    if msg.status.goal_id.id == "early-1":
        with news:
            early.append("result %s sum=%d" % (NAMES[msg.status.status], msg.result.sum))
            news.notify_all()


def on_handles_status(msg):
    with news:
        early.extend("status " + NAMES[s.status] for s in msg.status_list if s.goal_id.id == "early-1")
        news.notify_all()


subs = [rospy.Subscriber("handles/result", TwoIntsActionResult, on_result),
        rospy.Subscriber("handles/status", GoalStatusArray, on_handles_status)]
cancel_pub = rospy.Publisher("handles/cancel", GoalID, queue_size=10)
goal_pub = rospy.Publisher("handles/goal", TwoIntsActionGoal, queue_size=10)
deadline = time.monotonic() + 20
while time.monotonic() < deadline and not (cancel_pub.get_num_connections()
                                           and goal_pub.get_num_connections()
                                           and all(s.get_num_connections() for s in subs)):
    time.sleep(0.05)
cancel_pub.publish(GoalID(id="early-1"))
with news:
    news.wait_for(lambda: "status RECALLING" in early, 20)
goal = TwoIntsActionGoal()
goal.goal_id.id = "early-1"
goal.goal.a, goal.goal.b = 5, 5
goal_pub.publish(goal)
with news:
    news.wait_for(lambda: any(e.startswith("result") for e in early), 20)
say("early cancel", [e for e in early if e.startswith("result")])

# a goal for an action server nobody runs
nobody = actionlib.SimpleActionClient("nobody", TwoIntsAction)
start = time.monotonic()
found = nobody.wait_for_server(rospy.Duration(1.0))
waited = time.monotonic() - start
nobody.send_goal(TwoIntsGoal(a=1, b=1))
finished = nobody.wait_for_result(rospy.Duration(0.5))
say("unknown server", found, 1.0 <= waited < 5.0, finished, NAMES[nobody.get_state()])
say("client done")
'''

EXPECTED = [
    "simple server True",
    "goal1 SUCCEEDED sum=7 feedback=3 done_cb=True text=done",
    "goal2 feedback True ACTIVE",
    "goal2 PREEMPTED sum=-1 text=preempted",
    "goal3 after cancel SUCCEEDED sum=2 server says ['SUCCEEDED']",
    # the execute callback sees the preempt request first and ends the older goal itself
    "older goal PREEMPTED preempted",
    "newer goal SUCCEEDED sum=3",
    "handles server True",
    "handle goal a=-1 REJECTED negative sum=-1",
    "handle goal a=5 SUCCEEDED handled sum=15",
    "pending goal cancelled RECALLED recalled by request sum=-99",
    "early cancel ['result RECALLED sum=0']",
    "unknown server False True False PENDING",
    "client done",
]
