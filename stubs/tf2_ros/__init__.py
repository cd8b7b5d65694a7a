"""tf2_ros stand-in: Buffer, TransformListener and the broadcasters (behaviour in minros.tf)."""

# with the message and service classes tf2_ros's modules import, which its package hands on
from actionlib_msgs.msg import GoalStatus  # noqa: F401
from geometry_msgs.msg import TransformStamped  # noqa: F401
from minros.tf.broadcaster import StaticTransformBroadcaster, TransformBroadcaster  # noqa: F401
from minros.tf.buffer import *  # noqa: F403
from minros.tf.listener import TransformListener  # noqa: F401
from std_msgs.msg import Header  # noqa: F401
from tf2_msgs.msg import LookupTransformAction, LookupTransformGoal, TFMessage  # noqa: F401
from tf2_msgs.srv import FrameGraph, FrameGraphResponse  # noqa: F401
from tf2_py import *  # noqa: F403 (tf2_ros re-exports tf2_py, the exceptions included)


def __getattr__(name: str):
    # BufferClient/BufferServer sit on actionlib: imported when first used
    if name in ("BufferClient", "BufferServer"):
        import minros.tf2_buffer

        return getattr(minros.tf2_buffer, name)
    raise AttributeError(f"module 'tf2_ros' has no attribute {name!r}")
