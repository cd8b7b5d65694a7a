"""genpy.base: the fixed-size primitive types and their struct codes (minros.msgs.codegen)."""

from __future__ import annotations

from minros.msgs.codegen import SER_CODE

#: primitive type -> struct code (bool, char and byte as genpy writes them)
SIMPLE_TYPES_DICT = dict(SER_CODE)
SIMPLE_TYPES = list(SIMPLE_TYPES_DICT)


def is_simple(type_: str) -> bool:
    """Whether ``type_`` has a fixed size on the wire (every primitive but string)."""
    return type_ in SIMPLE_TYPES_DICT


__all__ = ["SIMPLE_TYPES_DICT", "SIMPLE_TYPES", "is_simple"]
