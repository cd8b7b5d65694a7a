"""turtle_tf_broadcaster.py: broadcast ``~turtle``'s pose as the frame ``<turtle>`` in
``world``, one transform per turtlesim Pose message (tf1 API, as the tutorial)."""

from __future__ import annotations

import sys

import rospy
import tf
import turtlesim.msg


def handle_turtle_pose(msg: turtlesim.msg.Pose, turtlename: str) -> None:
    br = tf.TransformBroadcaster()
    br.sendTransform((msg.x, msg.y, 0),
                     tf.transformations.quaternion_from_euler(0, 0, msg.theta),
                     rospy.Time.now(),
                     turtlename,
                     "world")


def main() -> int:
    rospy.init_node("turtle_tf_broadcaster")
    turtlename = rospy.get_param("~turtle")
    rospy.Subscriber(f"/{turtlename}/pose", turtlesim.msg.Pose, handle_turtle_pose, turtlename)
    rospy.spin()
    return 0


if __name__ == "__main__":
    from minros.tf.tools import run_tool

    sys.exit(run_tool("turtle_tf_broadcaster.py", main))
