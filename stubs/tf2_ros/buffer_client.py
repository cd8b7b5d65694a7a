"""tf2_ros.buffer_client stand-in (see minros.tf.buffer)."""

from minros.tf.buffer import *  # noqa: F403
