"""axclient (headless): send one goal to an action server and print what comes back.

    rosrun actionlib_tools axclient.py /action_name [pkg/TypeAction] [--goal YAML] [--timeout S]

ROS's axclient is a wxPython window; this one takes the goal as YAML (the fields of the
goal, as ``rostopic pub`` takes a message), prints each feedback and the result as YAML,
and exits with 0 when the goal succeeded. Ctrl-C cancels the goal. Without a type, the
type is read from the master (the server's ``/action_name/result`` topic).
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from typing import Any, List, Optional

import minros
from actionlib_msgs.msg import GoalStatus
from minros.actionlib import SimpleActionClient
from minros.actionlib_tools.dynamic_action import DynamicAction
from minros.actionlib_tools.library import yaml_msg_str
from minros.msgs.message import strify_message

STATES = {getattr(GoalStatus, n): n for n in ("PENDING", "ACTIVE", "PREEMPTED", "SUCCEEDED",
                                             "ABORTED", "REJECTED", "PREEMPTING", "RECALLING",
                                             "RECALLED", "LOST")}


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="axclient.py", description=__doc__.split("\n\n")[0])
    p.add_argument("action_name", help="the action's namespace, e.g. /fibonacci")
    p.add_argument("action_type", nargs="?", help="e.g. actionlib_tutorials/FibonacciAction "
                   "(read from the master when omitted)")
    p.add_argument("--goal", default="", help="the goal's fields as YAML, e.g. 'order: 5'")
    p.add_argument("--timeout", type=float, default=30.0,
                   help="seconds to wait for the server, and then for the result (default 30)")
    return p


def _type_from_master(name: str) -> Optional[str]:
    """The action type of the server publishing ``name/result``."""
    result_topic = name.rstrip("/") + "/result"
    for topic, type_name in minros.get_published_topics():
        if topic == result_topic and type_name.endswith("ActionResult"):
            return type_name[: -len("Result")]
    return None


def main(argv: Optional[List[str]] = None) -> int:
    argv = list(sys.argv if argv is None else argv)
    args = parser().parse_args(minros.myargv(argv)[1:])
    minros.init_node("axclient", argv=argv, anonymous=True)
    name = minros.resolve_name(args.action_name)
    type_name = args.action_type
    if not type_name:
        deadline = time.monotonic() + args.timeout
        while not (type_name := _type_from_master(name)) and time.monotonic() < deadline:
            time.sleep(0.2)
        if not type_name:
            print(f"error: no action server publishes {name}/result: give the action type "
                  "(pkg/NameAction)", file=sys.stderr)
            return 2
    try:
        action = DynamicAction(type_name)
        goal = yaml_msg_str(action.goal, args.goal)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except Exception as exc:  # noqa: BLE001 - fill errors name the field
        print(f"error: the goal does not fit {action.goal._type}: {exc}", file=sys.stderr)
        return 2
    client = SimpleActionClient(name, action.action)
    if not client.wait_for_server(minros.Duration(args.timeout)):
        print(f"error: action server {name} did not appear within {args.timeout:g} s",
              file=sys.stderr)
        return 1
    done = threading.Event()
    client.send_goal(goal, done_cb=lambda state, result: done.set(),
                     feedback_cb=lambda fb: print("feedback:\n" + _indent(strify_message(fb)),
                                                  flush=True))
    print(f"goal sent to {name}", flush=True)
    try:
        if not done.wait(args.timeout):
            print(f"no result within {args.timeout:g} s: cancelling the goal", file=sys.stderr)
            client.cancel_goal()
            done.wait(5.0)
    except KeyboardInterrupt:
        client.cancel_goal()
        done.wait(5.0)
    state = client.get_state()
    print(f"state: {STATES.get(state, state)}")
    result = client.get_result()
    if result is not None:
        print("result:\n" + _indent(strify_message(result)))
    return 0 if state == GoalStatus.SUCCEEDED else 1


def _indent(text: Any) -> str:
    return "\n".join("  " + line for line in str(text).splitlines()) if text else "  {}"


if __name__ == "__main__":
    sys.exit(main())
