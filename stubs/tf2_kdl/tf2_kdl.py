"""tf2_kdl.tf2_kdl stand-in (see minros.tf.kdl_transforms)."""

import PyKDL  # noqa: F401
import rospy  # noqa: F401
import tf2_ros  # noqa: F401
from geometry_msgs.msg import PointStamped  # noqa: F401
from minros.tf.kdl_transforms import *  # noqa: F403
