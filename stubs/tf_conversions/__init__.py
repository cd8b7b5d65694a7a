"""tf_conversions stand-in: posemath's conversions and PyKDL's names (behaviour in
minros.tf.posemath)."""

from __future__ import absolute_import  # noqa: F401, UP010 (ROS's module has the name)

from .posemath import *  # noqa: F403
