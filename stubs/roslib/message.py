"""roslib.message: message and service classes by name (genpy's lookup, minros.msgs)."""

from genpy.message import (  # noqa: F401
    DeserializationError,
    Message,
    SerializationError,
    check_type,
    fill_message_args,
    get_message_class,
    get_printable_message_args,
    get_service_class,
    strify_message,
)
from genpy.rostime import Duration, Time, TVal  # noqa: E402, F401
