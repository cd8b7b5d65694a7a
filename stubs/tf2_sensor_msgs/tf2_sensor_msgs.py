"""tf2_sensor_msgs.tf2_sensor_msgs stand-in (see minros.tf.cloud_transforms)."""

import PyKDL  # noqa: F401
import rospy  # noqa: F401
import tf2_ros  # noqa: F401
from minros.tf.cloud_transforms import *  # noqa: F403
from sensor_msgs.msg import PointCloud2  # noqa: F401
from sensor_msgs.point_cloud2 import create_cloud, read_points  # noqa: F401
