#!/usr/bin/env python3
"""Send a navigation goal to move_base and wait for the result (the classic actionlib client).

    minros sim                                   # or any move_base, e.g. a TurtleBot3's
    python examples/sim/send_goal.py 2.0 1.0     # x y [yaw_degrees] [frame], in the map frame

The same script runs under ROS's own rospy, unmodified.
"""

import math
import sys

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal


def send_goal(x, y, yaw=0.0, frame="map"):
    client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
    rospy.loginfo("Waiting for the move_base action server...")
    if not client.wait_for_server(rospy.Duration(30)):
        rospy.logerr("move_base did not come up: is 'minros sim' (or move_base) running?")
        return None

    goal = MoveBaseGoal()
    goal.target_pose.header.frame_id = frame
    goal.target_pose.header.stamp = rospy.Time.now()
    goal.target_pose.pose.position.x = x
    goal.target_pose.pose.position.y = y
    goal.target_pose.pose.orientation.z = math.sin(yaw / 2.0)
    goal.target_pose.pose.orientation.w = math.cos(yaw / 2.0)

    rospy.loginfo("Sending goal (%.2f, %.2f) in %s", x, y, frame)
    client.send_goal(goal)
    if not client.wait_for_result(rospy.Duration(120)):
        client.cancel_goal()
        rospy.logerr("The goal took too long; cancelled")
        return None
    return client.get_state(), client.get_goal_status_text()


if __name__ == "__main__":
    try:
        rospy.init_node("send_goal")
        args = rospy.myargv(sys.argv)[1:]
        x = float(args[0]) if len(args) > 0 else 2.0
        y = float(args[1]) if len(args) > 1 else 0.0
        yaw = math.radians(float(args[2])) if len(args) > 2 else 0.0
        frame = args[3] if len(args) > 3 else "map"
        outcome = send_goal(x, y, yaw, frame)
        if outcome is None:
            sys.exit(1)
        state, text = outcome
        name = {GoalStatus.SUCCEEDED: "SUCCEEDED", GoalStatus.ABORTED: "ABORTED",
                GoalStatus.PREEMPTED: "PREEMPTED"}.get(state, str(state))
        print(f"Result: {name}: {text}")
        sys.exit(0 if state == GoalStatus.SUCCEEDED else 2)
    except rospy.ROSInterruptException:
        rospy.loginfo("Navigation test finished.")
