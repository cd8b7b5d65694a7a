"""rospy.impl.tcpros_service: the TCPROS protocol of services and the check of a service connection (minros.rospy_internals.tcpros_service)."""

from minros.rospy_internals.tcpros_service import (  # noqa: F401
    BIDIRECTIONAL,
    DEFAULT_BUFF_SIZE,
    SERVICE_ANYTYPE,
    Service,
    ServiceProxy,
    TCPROSServiceClient,
    TCPROSTransport,
    TCPROSTransportProtocol,
    TCPService,
    convert_return_to_response,
    get_service_manager,
    service_connection_handler,
    wait_for_service,
)
