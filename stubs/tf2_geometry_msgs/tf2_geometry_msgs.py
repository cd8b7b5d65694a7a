"""tf2_geometry_msgs.tf2_geometry_msgs stand-in (see minros.tf.geometry)."""

from minros.tf.geometry import *  # noqa: F403
