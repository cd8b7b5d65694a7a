"""rospy.exceptions: the rospy exception hierarchy (minros.exceptions)."""

from minros.exceptions import (  # noqa: F401
    ROSException,
    ROSInitException,
    ROSInternalException,
    ROSInterruptException,
    ROSSerializationException,
    ROSTimeMovedBackwardsException,
    TransportException,
    TransportInitError,
    TransportTerminated,
)
