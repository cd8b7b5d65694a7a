"""tf2_kdl stand-in: importing it registers PyKDL types with tf2_ros (see
minros.tf.kdl_transforms)."""

from .tf2_kdl import *  # noqa: F403
