"""tf2_ros.buffer_client stand-in: BufferClient (see minros.tf2_buffer)."""

from minros.tf.buffer import *  # noqa: F403
from minros.tf2_buffer.client import BufferClient  # noqa: F401
