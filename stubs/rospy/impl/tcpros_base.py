"""rospy.impl.tcpros_base: TCPROS transports, their protocols and a TCP server (minros.rospy_internals.tcpros_base)."""

from minros.rospy_internals.tcpros_base import (  # noqa: F401
    BIDIRECTIONAL,
    DEFAULT_BUFF_SIZE,
    TCPROS,
    TCPROSServer,
    TCPROSTransport,
    TCPROSTransportProtocol,
    TCPServer,
    Transport,
    TransportException,
    TransportInitError,
    TransportTerminated,
    get_tcpros_server_address,
    init_tcpros_server,
    recv_buff,
    start_tcpros_server,
)
