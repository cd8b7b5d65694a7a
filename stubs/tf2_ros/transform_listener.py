"""tf2_ros.transform_listener stand-in (see minros.tf.listener)."""

from minros.tf.listener import *  # noqa: F403
from tf2_msgs.msg import TFMessage  # noqa: F401
