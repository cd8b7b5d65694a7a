"""rospy.impl.tcpros_pubsub: the TCPROS protocol of topics and rospy's TCPROS handler (minros.rospy_internals.tcpros_pubsub)."""

from minros.rospy_internals.core import logdebug, logerr, logwarn, rospyerr  # noqa: F401
from minros.rospy_internals.tcpros_base import start_tcpros_server  # noqa: F401
from minros.rospy_internals.tcpros_pubsub import (  # noqa: F401
    DEFAULT_BUFF_SIZE,
    INBOUND,
    OUTBOUND,
    TCPROS,
    TOPIC_ANYTYPE,
    ProtocolHandler,
    QueuedConnection,
    TCPROSHandler,
    TCPROSPub,
    TCPROSSub,
    TCPROSTransport,
    TCPROSTransportProtocol,
    _configure_pub_socket,
    check_if_still_publisher,
    get_tcpros_server_address,
    robust_connect_subscriber,
)
