"""Record a robot's ground-truth poses for a while, as JSON on stdout:
``python sim_watch.py SECONDS [ROBOT_NAMESPACE]`` (minros's or Debian's Python)."""

import json
import sys
import time

import rospy
from nav_msgs.msg import Odometry

seconds = float(sys.argv[1])
prefix = sys.argv[2] + "/" if len(sys.argv) > 2 and sys.argv[2] else ""
poses = []
rospy.init_node("sim_watch", anonymous=True)
rospy.Subscriber(prefix + "base_pose_ground_truth", Odometry,
                 lambda m: poses.append((m.pose.pose.position.x, m.pose.pose.position.y)))
deadline = time.monotonic() + seconds
while time.monotonic() < deadline and not rospy.is_shutdown():
    time.sleep(0.05)
print(json.dumps(poses[::3]), flush=True)
