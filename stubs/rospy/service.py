"""rospy.service: ServiceException, the service record and the service manager
(minros.client.services, minros.rospy_internals). Like rospy's module, its namespace also has
rospy.core's names (``from rospy.core import *``) and rospy.impl.transport's."""

import logging

from minros.client.services import Service, ServiceProxy  # noqa: F401
from minros.exceptions import ServiceException  # noqa: F401
from minros.rospy_internals import core as _core
from minros.rospy_internals.registration import (  # noqa: F401
    Registration,
    get_registration_listeners,
    set_service_manager,
)
from minros.rospy_internals.service import ServiceImpl, ServiceManager, _Service  # noqa: F401
from minros.rospy_internals.transport import (  # noqa: F401
    BIDIRECTIONAL,
    INBOUND,
    OUTBOUND,
    DeadTransport,
    ProtocolHandler,
    Transport,
)

logger = logging.getLogger("rospy.service")
_core.star_import(globals())
