"""``from actionlib import *`` gives what ROS's actionlib gives: its package has no __all__ and
star-imports its four modules, so their public names and the modules they import come along
(smach_ros does ``from actionlib import *`` and then uses ``threading``)."""

from __future__ import annotations

import json
import subprocess

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

STAR = ("import json\nns = {}\nexec('from actionlib import *', ns)\n"
        "print(json.dumps(sorted(k for k in ns if k != '__builtins__')))\n")

#: Debian's python3-actionlib 1.14.0 (the interop test below checks it against the package)
ROS_NAMES = [
    "ActionClient", "ActionException", "ActionServer", "ClientGoalHandle", "CommState",
    "CommStateMachine", "GoalID", "GoalIDGenerator", "GoalManager", "GoalStatus",
    "GoalStatusArray", "HandleTrackerDeleter", "Header", "INVALID_TRANSITION", "NO_TRANSITION",
    "ServerGoalHandle", "SimpleActionClient", "SimpleActionServer", "SimpleGoalState",
    "StatusTracker", "TerminalState", "action_client", "action_server", "exceptions",
    "g_goal_id", "get_name_of_constant", "goal_id_generator", "handle_tracker_deleter",
    "nop_cb", "rospy", "server_goal_handle", "simple_action_client", "simple_action_server",
    "status_tracker", "threading", "time", "traceback", "weakref"]


def _names(python: str, env=None) -> list:
    out = subprocess.run([python, "-c", STAR], capture_output=True, text=True, timeout=60,
                         env=env)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_star_import_gives_ros_names():
    assert _names(PYTHON) == ROS_NAMES


def test_what_smach_ros_uses_after_a_star_import():
    ns: dict = {}
    exec("from actionlib import *", ns)
    lock = ns["threading"].Lock()
    assert lock.acquire(blocking=False)
    assert ns["SimpleActionClient"].__name__ == "SimpleActionClient"
    assert ns["g_goal_id"] >= 0


def test_the_names_are_debians():
    require_reference()
    assert _names(REFERENCE_PYTHON, reference_env({})) == ROS_NAMES
