"""genpy.message: the Message base class, type checks, YAML filling and type lookup
(minros.msgs.message, minros.msgs.fill, minros.msgs.registry)."""

from __future__ import annotations

from typing import Any

from minros.exceptions import DeserializationError, MessageException, SerializationError
from minros.msgs.fill import (  # noqa: F401
    _fill_message_args,
    _fill_val,
    fill_message_args,
    get_printable_message_args,
)
from minros.msgs.importer import install_import_hook
from minros.msgs.message import (  # noqa: F401
    Message,
    RosMsgUnicodeErrors,
    check_type,
    isstring,
    strify_message,
    struct_I,
)
from minros.msgs.registry import import_class
from minros.msgs.tval import Duration, Time, TVal

# genpy finds classes by importing <pkg>.msg: packages on ROS_PACKAGE_PATH need the hook
install_import_hook()

__all__ = ["Message", "MessageException", "DeserializationError", "SerializationError",
           "check_type", "get_message_class", "get_service_class", "strify_message",
           "fill_message_args", "get_printable_message_args", "isstring", "struct_I",
           "Time", "Duration", "TVal"]


def get_message_class(message_type: str, reload_on_error: bool = False) -> Any:
    """The class of ``pkg/Type``, or None when there is none (genpy's contract)."""
    return import_class(message_type, "msg")


def get_service_class(service_type: str, reload_on_error: bool = False) -> Any:
    """The class of service ``pkg/Type``, or None when there is none (genpy's contract)."""
    return import_class(service_type, "srv")

from genpy.base import is_simple  # noqa: E402, F401
