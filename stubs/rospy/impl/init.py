"""rospy.impl.init: the node's start and console handler (minros.rospy_internals.init)."""

from minros.rospy_internals.core import is_shutdown, rospyerr, signal_shutdown  # noqa: F401
from minros.rospy_internals.init import (  # noqa: F401
    DEFAULT_MASTER_PORT,
    DEFAULT_MASTER_URI,
    DEFAULT_NODE_PORT,
    RosStreamHandler,
    start_node,
)
from minros.rospy_internals.masterslave import ROSHandler  # noqa: F401
from minros.rospy_internals.tcpros import init_tcpros  # noqa: F401
