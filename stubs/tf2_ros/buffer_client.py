"""tf2_ros.buffer_client stand-in: BufferClient (see minros.tf2_buffer)."""

from actionlib_msgs.msg import GoalStatus  # noqa: F401
from minros.tf.buffer import *  # noqa: F403
from minros.tf2_buffer.client import BufferClient  # noqa: F401
from tf2_msgs.msg import LookupTransformAction, LookupTransformGoal  # noqa: F401 - its action
