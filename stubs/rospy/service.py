"""rospy.service: ServiceException (minros.client.services)."""

from minros.exceptions import ServiceException  # noqa: F401
