"""rospy.impl.tcpros_base: TCPROS transports, their protocols and a TCP server
(minros.rospy_internals.tcpros_base). Like rospy's module, its namespace also has rospy.core's
names (``from rospy.core import *``) and the helpers it imports."""

import logging
from errno import EAGAIN, EWOULDBLOCK  # noqa: F401

from minros.exceptions import (  # noqa: F401
    DeserializationError,
    ROSInternalException,
    ServiceException,
)
from minros.msgs.message import Message  # noqa: F401
from minros.rospy_internals import core as _core
from minros.rospy_internals.msg import deserialize_messages, serialize_message  # noqa: F401
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
from rosgraph.network import read_ros_handshake_header, write_ros_handshake_header  # noqa: F401

logger = logging.getLogger("rospy.tcpros")
python3 = True  # rospy's flag of a Python 3 interpreter
_core.star_import(globals())
