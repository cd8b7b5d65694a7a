"""Stand-in for genpy: what scripts and genpy-generated message modules import from it,
served by minros.msgs."""

from __future__ import annotations

from minros.exceptions import DeserializationError, MessageException, SerializationError
from minros.msgs.message import Message, struct_I
from minros.msgs.tval import Duration, Time, TVal

from . import message, rostime  # noqa: F401 - genpy's __init__ loads both

__all__ = ["Time", "Duration", "TVal", "Message", "SerializationError", "DeserializationError",
           "MessageException", "struct_I"]
