#!/usr/bin/env python3
"""An action client: sends a countdown goal, prints the feedback and the result.

    python examples/actionlib/countdown_client.py [N]
"""

import sys

import rospy
from actionlib import SimpleActionClient
from actionlib.msg import TestAction, TestGoal
from actionlib_msgs.msg import GoalStatus

#: GoalStatus's state numbers by name (SUCCEEDED, PREEMPTED, ...)
STATES = {getattr(GoalStatus, name): name for name in dir(GoalStatus) if name.isupper()}


def main() -> None:
    rospy.init_node("countdown_client")
    count = int(rospy.myargv()[1]) if len(rospy.myargv()) > 1 else 5
    client = SimpleActionClient("countdown", TestAction)
    if not client.wait_for_server(rospy.Duration(10)):
        rospy.logerr("no action server on /countdown")
        sys.exit(1)
    client.send_goal(TestGoal(goal=count),
                     feedback_cb=lambda feedback: rospy.loginfo("feedback: %d", feedback.feedback))
    client.wait_for_result(rospy.Duration(count + 10))
    rospy.loginfo("result: %s (%s, %r)", client.get_result().result,
                  STATES.get(client.get_state(), "?"), client.get_goal_status_text())


if __name__ == "__main__":
    main()
