"""tf2_geometry_msgs stand-in: importing it registers geometry_msgs conversions with tf2_ros."""

from .tf2_geometry_msgs import *  # noqa: F403
