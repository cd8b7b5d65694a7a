"""genpy.message: the Message base class and type lookup, served by minros.msgs."""

from __future__ import annotations

from minros.exceptions import DeserializationError, MessageException, SerializationError
from minros.msgs import Message, check_type, get_message_class, get_service_class, strify_message

__all__ = ["Message", "MessageException", "DeserializationError", "SerializationError",
           "check_type", "get_message_class", "get_service_class", "strify_message"]
