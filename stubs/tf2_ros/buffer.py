"""tf2_ros.buffer stand-in (see minros.tf.buffer)."""

from minros.tf.buffer import *  # noqa: F403
