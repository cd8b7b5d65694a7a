"""tf2's buffer over an action: ``BufferServer`` answers tf2_msgs/LookupTransform goals from a
local tf2 Buffer, ``BufferClient`` is a BufferInterface whose lookups are such goals, as
tf2_ros's (a light client: no /tf subscription of its own). ``rosrun tf2_ros buffer_server``
runs the server as a node (``minros.nodes.tf2_ros.buffer_server``)."""

from minros.tf2_buffer.client import BufferClient
from minros.tf2_buffer.server import BufferServer

__all__ = ["BufferClient", "BufferServer"]
