"""tf_conversions stand-in: posemath's conversions and PyKDL's names (behaviour in
minros.tf.posemath)."""

from .posemath import *  # noqa: F403
