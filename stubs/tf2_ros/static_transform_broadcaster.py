"""tf2_ros.static_transform_broadcaster stand-in (see minros.tf.broadcaster)."""

from geometry_msgs.msg import TransformStamped  # noqa: F401
from minros.tf.broadcaster import *  # noqa: F403
from tf2_msgs.msg import TFMessage  # noqa: F401
