"""rospy.impl.tcpros: the node's TCPROS handler."""

from __future__ import annotations

from .tcpros_base import DEFAULT_BUFF_SIZE  # noqa: F401
from .tcpros_pubsub import TCPROSHandler

_handler = TCPROSHandler()


def init_tcpros(port: int = 0) -> TCPROSHandler:
    """rospy starts its TCPROS server here; a minros node starts its own (with the node)."""
    return _handler


def get_tcpros_handler() -> TCPROSHandler:
    return _handler
