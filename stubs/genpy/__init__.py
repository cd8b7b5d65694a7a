"""Stand-in for genpy: the names scripts and tools import from it, served by minros.msgs."""

from __future__ import annotations

from typing import Any

from minros.exceptions import DeserializationError, MessageException, SerializationError
from minros.msgs import Duration, Time, TVal

__all__ = ["Message", "Time", "Duration", "TVal", "MessageException", "DeserializationError",
           "SerializationError"]


def __getattr__(name: str) -> Any:
    if name == "Message":  # loaded lazily, as minros.msgs does
        from minros.msgs import Message

        return Message
    raise AttributeError(f"module 'genpy' has no attribute '{name}'")
