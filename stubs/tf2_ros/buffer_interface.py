"""tf2_ros.buffer_interface stand-in (see minros.tf.buffer)."""

from minros.tf.buffer import *  # noqa: F403
