"""rospy.impl.tcpros_pubsub: the TCPROS protocol of topics and rospy's TCPROS handler (minros.rospy_internals.tcpros_pubsub)."""

from minros.rospy_internals.tcpros_pubsub import (  # noqa: F401
    DEFAULT_BUFF_SIZE,
    INBOUND,
    OUTBOUND,
    TCPROS,
    TOPIC_ANYTYPE,
    ProtocolHandler,
    TCPROSHandler,
    TCPROSPub,
    TCPROSSub,
    TCPROSTransport,
    TCPROSTransportProtocol,
    _configure_pub_socket,
    get_tcpros_server_address,
)
