#!/usr/bin/env python3
"""An action server: counts down from the goal, one step every 0.2 s, with feedback.

    python examples/actionlib/countdown_server.py

The action is actionlib/Test (goal, result and feedback are each one int32), served under
/countdown: the topics /countdown/goal, /cancel, /status, /feedback and /result.
"""

import rospy
from actionlib import SimpleActionServer
from actionlib.msg import TestAction, TestFeedback, TestResult


class Countdown:
    def __init__(self) -> None:
        self.server = SimpleActionServer("countdown", TestAction, execute_cb=self.execute,
                                         auto_start=False)
        self.server.start()

    def execute(self, goal) -> None:
        rate = rospy.Rate(5)
        rospy.loginfo("counting down from %d", goal.goal)
        for left in range(goal.goal, 0, -1):
            if self.server.is_preempt_requested() or rospy.is_shutdown():
                rospy.loginfo("preempted at %d", left)
                self.server.set_preempted(TestResult(result=left))
                return
            self.server.publish_feedback(TestFeedback(feedback=left))
            rate.sleep()
        self.server.set_succeeded(TestResult(result=goal.goal), "lift-off")


if __name__ == "__main__":
    rospy.init_node("countdown_server")
    Countdown()
    rospy.spin()
