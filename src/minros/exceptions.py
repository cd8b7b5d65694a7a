"""The exception hierarchy of rospy and genpy, in one place.

Every minros layer raises these, so `except rospy.ROSException` and
`except genpy.DeserializationError`-style handlers in existing code keep working.
"""

from __future__ import annotations


class ROSException(Exception):
    """Base exception of the ROS client library."""


class ROSSerializationException(ROSException):
    """A message could not be serialized or deserialized."""


class ROSInitException(ROSException):
    """The node could not be initialised (bad name, no master, ...)."""


class ROSInterruptException(ROSException, KeyboardInterrupt):
    """An operation was interrupted by shutdown (Ctrl-C, rosnode kill, ...)."""


class ROSTimeMovedBackwardsException(ROSInterruptException):
    """Simulated time jumped backwards while a node was sleeping."""

    def __init__(self, time: float) -> None:
        self.time = time  # how far back, in seconds
        super().__init__("ROS time moved backwards")


class ROSInternalException(Exception):
    """Base of exceptions that are internal to the middleware."""


class TransportException(ROSInternalException):
    """A transport (TCPROS connection) failed."""


class TransportTerminated(TransportException):
    """A connection was closed."""


class TransportInitError(TransportException):
    """A transport could not be set up (bind, connect, handshake)."""


class ServiceException(ROSException):
    """A service call failed, or a service handler wants to report an error."""


# genpy's names: generated message code and tools catch these.
class MessageException(Exception):
    """Base of message (de)serialization and type errors (genpy.MessageException)."""


class DeserializationError(MessageException, ROSSerializationException):
    """Bytes could not be turned into a message: truncated, padded or lying lengths."""


class SerializationError(MessageException, ROSSerializationException):
    """A message could not be turned into bytes; the text names the offending field."""


# A traceback names an exception by its class's module: name them as ROS does, so a script's
# uncaught exception reads as under ROS (rospy.exceptions.ROSInterruptException, ...), and
# pickles point at the stand-ins in stubs/ that re-export them.
for _module, _classes in (
        ("rospy.exceptions", (ROSException, ROSSerializationException, ROSInitException,
                              ROSInterruptException, ROSTimeMovedBackwardsException,
                              ROSInternalException, TransportException, TransportTerminated,
                              TransportInitError)),
        ("rospy.service", (ServiceException,)),
        ("genpy.message", (MessageException, DeserializationError, SerializationError))):
    for _cls in _classes:
        _cls.__module__ = _module
del _module, _classes, _cls
