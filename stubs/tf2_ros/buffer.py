"""tf2_ros.buffer stand-in (see minros.tf.buffer)."""

from minros.tf.buffer import *  # noqa: F403
from tf2_msgs.srv import FrameGraph, FrameGraphResponse  # noqa: F401 - the service Buffer serves
