"""tf2_ros.buffer_interface stand-in (see minros.tf.buffer)."""

from minros.tf.buffer import *  # noqa: F403
from std_msgs.msg import Header  # noqa: F401
