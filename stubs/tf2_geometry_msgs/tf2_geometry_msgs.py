"""tf2_geometry_msgs.tf2_geometry_msgs stand-in (see minros.tf.geometry)."""

from geometry_msgs.msg import PointStamped, PoseStamped, Vector3Stamped, WrenchStamped  # noqa: F401
from minros.tf.geometry import *  # noqa: F403
