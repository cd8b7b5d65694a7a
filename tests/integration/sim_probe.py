"""What a client sees of a running `minros sim`, as JSON on stdout (run by minros's Python or
by Debian's, with its rospy and tf2_ros): ``python sim_probe.py [ROBOT_NAMESPACE]``."""

import json
import sys

import rospy
import tf2_ros
from nav_msgs.msg import OccupancyGrid, Odometry
from nav_msgs.srv import GetMap
from sensor_msgs.msg import LaserScan

ns = sys.argv[1] if len(sys.argv) > 1 else ""
prefix = ns + "/" if ns else ""
rospy.init_node("sim_probe", anonymous=True)
buffer = tf2_ros.Buffer()
listener = tf2_ros.TransformListener(buffer)
scan = rospy.wait_for_message(prefix + "scan", LaserScan, timeout=20)
odom = rospy.wait_for_message(prefix + "odom", Odometry, timeout=20)
grid = rospy.wait_for_message("/map", OccupancyGrid, timeout=20)
rospy.wait_for_service("/static_map", timeout=20)
served = rospy.ServiceProxy("/static_map", GetMap)().map
laser = buffer.lookup_transform("map", prefix + "base_scan", rospy.Time(0), rospy.Duration(10))
chain = buffer.lookup_transform(prefix + "odom", prefix + "base_footprint", rospy.Time(0),
                                rospy.Duration(10))
description = rospy.get_param(prefix + "robot_description", "")
print(json.dumps({
    "scan": {"beams": len(scan.ranges), "frame": scan.header.frame_id,
             "angle_min": scan.angle_min, "angle_increment": scan.angle_increment,
             "range_min": scan.range_min, "range_max": scan.range_max,
             "ahead": scan.ranges[0], "finite": sum(1 for r in scan.ranges if abs(r) != float("inf"))},
    "odom": {"frame": odom.header.frame_id, "child": odom.child_frame_id},
    "map": {"width": grid.info.width, "height": grid.info.height,
            "resolution": grid.info.resolution, "frame": grid.header.frame_id,
            "occupied": sum(1 for v in grid.data if v == 100),
            "served_equal": list(served.data) == list(grid.data)},
    "laser_in_map": [laser.transform.translation.x, laser.transform.translation.y,
                     laser.transform.translation.z],
    "odom_chain": chain.header.frame_id + "->" + chain.child_frame_id,
    "urdf": description.startswith("<?xml") and "<robot" in description,
}), flush=True)
