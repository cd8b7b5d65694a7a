"""rospy.impl.tcpros: the node's TCPROS handler (minros.rospy_internals.tcpros)."""

from minros.rospy_internals.tcpros import (  # noqa: F401
    DEFAULT_BUFF_SIZE,
    TCPROSHandler,
    get_tcpros_handler,
    init_tcpros,
)
from minros.rospy_internals.tcpros_base import init_tcpros_server  # noqa: F401
