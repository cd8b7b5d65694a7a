"""tf2_ros.static_transform_broadcaster stand-in (see minros.tf.broadcaster)."""

from minros.tf.broadcaster import *  # noqa: F403
