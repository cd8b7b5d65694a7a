"""tf2_ros.transform_broadcaster stand-in (see minros.tf.broadcaster)."""

from minros.tf.broadcaster import *  # noqa: F403
