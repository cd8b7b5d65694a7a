"""laser_geometry.laser_geometry stand-in (see minros.laser_geometry)."""

import numpy as np  # noqa: F401

import rospy  # noqa: F401
import sensor_msgs.point_cloud2 as pc2  # noqa: F401
from minros.laser_geometry import LaserProjection  # noqa: F401
from sensor_msgs.msg import PointCloud2  # noqa: F401
