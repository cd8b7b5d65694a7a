"""tf_conversions.posemath stand-in (see minros.tf.posemath); like ROS's module it also
offers PyKDL's names, tf, tf.transformations, rospy and numpy."""

import numpy  # noqa: F401

import rospy  # noqa: F401
import tf  # noqa: F401
from geometry_msgs.msg import Point, Pose, Quaternion  # noqa: F401
from minros.tf.posemath import (  # noqa: F401
    fromCameraParams,
    fromMatrix,
    fromMsg,
    fromTf,
    toMatrix,
    toMsg,
    toTf,
)
from PyKDL import *  # noqa: F403
from tf import transformations  # noqa: F401
