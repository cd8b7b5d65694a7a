"""rospy.impl.transport: the base of rospy's connections and protocol handlers (minros.rospy_internals.transport)."""

from minros.rospy_internals.transport import (  # noqa: F401
    BIDIRECTIONAL,
    INBOUND,
    OUTBOUND,
    DeadTransport,
    ProtocolHandler,
    Transport,
)
