"""rospy.service: ServiceException, the service record and the service manager
(minros.client.services, minros.rospy_internals)."""

from minros.client.services import Service, ServiceProxy  # noqa: F401
from minros.exceptions import ServiceException  # noqa: F401
from minros.rospy_internals.service import ServiceImpl, ServiceManager, _Service  # noqa: F401
