"""genpy.base: the fixed-size primitive types and their struct codes (minros.msgs.pygen)."""

from minros.msgs.pygen import SIMPLE_TYPES, SIMPLE_TYPES_DICT, is_simple

__all__ = ["SIMPLE_TYPES_DICT", "SIMPLE_TYPES", "is_simple"]
