"""rospy.service: ServiceException (minros.services)."""

from minros.exceptions import ServiceException  # noqa: F401
