"""rospy.impl.tcpros_service: the TCPROS protocol of services and the check of a service connection (minros.rospy_internals.tcpros_service)."""

import logging

from minros.exceptions import (  # noqa: F401
    ROSException,
    ROSInterruptException,
    ServiceException,
    TransportInitError,
    TransportTerminated,
)
from minros.rospy_internals.core import logdebug, logerr, loginfo, logwarn  # noqa: F401
from minros.rospy_internals.names import isstring  # noqa: F401
from minros.rospy_internals.service import ServiceImpl  # noqa: F401
from minros.rospy_internals.tcpros_base import (  # noqa: F401
    get_tcpros_server_address,
    recv_buff,
    start_tcpros_server,
)
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

logger = logging.getLogger("rospy.service")
