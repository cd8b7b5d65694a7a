"""``rosrun turtlesim mimic input:=A output:=B``: make turtle B copy turtle A's motion.

As mimic.cpp: node ``turtle_mimic``; subscribes ``input/pose`` and publishes ``output/cmd_vel``
(queue 1 each) with linear.x = pose.linear_velocity and angular.z = pose.angular_velocity.
``input``/``output`` are namespaces (C++ NodeHandle("input")), so the remapping ``input:=ns``
moves every name inside them; rospy only remaps whole names, hence the explicit resolution.
"""

from __future__ import annotations

import sys
from typing import Any, List


def twist_for_pose(pose: Any) -> Any:
    """The Twist that replays ``pose``'s velocities."""
    from geometry_msgs.msg import Twist

    twist = Twist()
    twist.angular.z = pose.angular_velocity
    twist.linear.x = pose.linear_velocity
    return twist


def in_namespace(namespace: str, name: str) -> str:
    """Resolve ``name`` inside the (remappable) namespace ``namespace``, as NodeHandle(ns) does."""
    import rospy

    ns = rospy.resolve_name(namespace)
    return rospy.resolve_name(ns.rstrip("/") + "/" + name)


def main(argv: List[str] | None = None) -> int:
    import rospy
    from geometry_msgs.msg import Twist
    from turtlesim.msg import Pose

    full_argv = list(sys.argv if argv is None else argv)
    rospy.init_node("turtle_mimic", argv=full_argv)
    pub = rospy.Publisher(in_namespace("output", "cmd_vel"), Twist, queue_size=1)
    rospy.Subscriber(in_namespace("input", "pose"), Pose,
                     lambda pose: pub.publish(twist_for_pose(pose)), queue_size=1)
    rospy.spin()
    return 0


if __name__ == "__main__":
    from minros.nodes.turtlesim import run_tool

    sys.exit(run_tool("mimic", main))
