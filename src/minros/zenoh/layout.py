"""Is this one serialized message of that type? Checked by walking lengths, building nothing.

A bridge passes bytes from Zenoh to ROS without deserializing them; a peer's garbage would
then reach every subscriber, each of which would log its own error for each message. The
check walks the fields the way a deserializer would (fixed-size runs skipped, string and
array lengths read and bounded by the bytes left) and wants every byte used: a 1080p image
costs a handful of steps, not a copy of its pixels.
"""

from __future__ import annotations

import struct
from typing import Any, Callable, Dict, List, Optional, Tuple

__all__ = ["Malformed", "checker", "slot_types_from_classes"]

_U32 = struct.Struct("<I")
_PRIMITIVES = {
    "bool": 1, "int8": 1, "uint8": 1, "byte": 1, "char": 1, "int16": 2, "uint16": 2,
    "int32": 4, "uint32": 4, "float32": 4, "int64": 8, "uint64": 8, "float64": 8,
    "time": 8, "duration": 8,
}

#: type name -> its fields' types, e.g. ['std_msgs/Header', 'uint8[]']
SlotTypes = Callable[[str], List[str]]


class Malformed(ValueError):
    """The bytes are not one message of the type; the text says where."""


# An op is (code, a, b): 0 skip a bytes; 1 string; 2 array of a-byte elements, counted;
# 3 a fixed count a of the walker b; 4 a counted array of walker b with minimum size a;
# 5 the walker b once.
_Op = Tuple[int, int, Any]


class _Type:
    __slots__ = ("fixed", "minimum", "ops")

    def __init__(self, fixed: Optional[int], minimum: int, ops: List[_Op]) -> None:
        self.fixed = fixed  # size when every message of the type has the same size
        self.minimum = minimum
        self.ops = ops


def _walk(ops: List[_Op], data: Any, pos: int, end: int) -> int:
    unpack = _U32.unpack_from
    for code, a, b in ops:
        if code == 0:
            pos += a
        elif code == 1:
            if pos + 4 > end:
                raise Malformed(f"a string length at byte {pos} runs past the end ({end})")
            pos += 4 + unpack(data, pos)[0]
        elif code == 2:
            if pos + 4 > end:
                raise Malformed(f"an array length at byte {pos} runs past the end ({end})")
            pos += 4 + unpack(data, pos)[0] * a
        elif code == 3:
            for _ in range(a):
                pos = _walk(b, data, pos, end)
        else:
            if code == 4:
                if pos + 4 > end:
                    raise Malformed(f"an array length at byte {pos} runs past the end ({end})")
                count = unpack(data, pos)[0]
                pos += 4
                if count * a > end - pos:
                    raise Malformed(f"an array of {count} elements at byte {pos} cannot fit "
                                    f"in the {end - pos} bytes left")
            else:
                count = 1
            for _ in range(count):
                pos = _walk(b, data, pos, end)
        if pos > end:
            raise Malformed(f"a field ends at byte {pos}, past the end ({end})")
    return pos


def _compile(type_name: str, slot_types: SlotTypes, memo: Dict[str, _Type]) -> _Type:
    known = memo.get(type_name)
    if known is not None:
        return known
    if len(memo) > 10000:
        raise Malformed("message definition too deep or too large")
    ops: List[_Op] = []
    fixed: Optional[int] = 0
    minimum = 0

    def skip(n: int) -> None:
        if ops and ops[-1][0] == 0:
            ops[-1] = (0, ops[-1][1] + n, None)
        elif n:
            ops.append((0, n, None))

    for field in slot_types(type_name):
        base, bracket, rest = field.partition("[")
        count: Optional[int] = None
        if bracket:
            size = rest.rstrip("]")
            count = int(size) if size else -1
        if base in _PRIMITIVES:
            elem = _Type(_PRIMITIVES[base], _PRIMITIVES[base], [(0, _PRIMITIVES[base], None)])
        elif base == "string":
            elem = _Type(None, 4, [(1, 0, None)])
        else:
            elem = _compile(base, slot_types, memo)
        if count is None:  # one value
            if elem.fixed is not None:
                skip(elem.fixed)
            else:
                ops.extend(elem.ops)
                fixed = None
            minimum += elem.minimum
        elif count >= 0:  # a fixed-length array
            if elem.fixed is not None:
                skip(elem.fixed * count)
            else:
                ops.append((3, count, elem.ops))
                fixed = None
            minimum += elem.minimum * count
        else:  # a counted array
            if elem.fixed is not None:
                ops.append((2, elem.fixed, None))
            else:
                ops.append((4, max(1, elem.minimum), elem.ops))
            fixed = None
            minimum += 4
        if fixed is not None and elem.fixed is not None:
            fixed += elem.fixed * (1 if count is None else max(count, 0))
    compiled = _Type(fixed, minimum, ops)
    memo[type_name] = compiled
    return compiled


def checker(type_name: str, slot_types: SlotTypes) -> Callable[[Any], None]:
    """A function raising Malformed unless its argument (bytes-like) is exactly one message
    of ``type_name``. ``slot_types(name)`` gives a type's field types (genpy's
    ``_slot_types``); KeyError/LookupError from it propagate (a type that cannot be checked)."""
    compiled = _compile(type_name, slot_types, {})
    if compiled.fixed is not None:
        size = compiled.fixed

        def check_fixed(data: Any) -> None:
            if len(data) != size:
                raise Malformed(f"{len(data)} bytes where {type_name} has {size}")
        return check_fixed
    ops = compiled.ops

    def check(data: Any) -> None:
        end = len(data)
        try:
            pos = _walk(ops, data, 0, end)
        except struct.error as exc:
            raise Malformed(str(exc)) from None
        if pos != end:
            raise Malformed(f"{end - pos} bytes left over after one {type_name}")
    return check


def slot_types_from_classes(classes: Dict[str, Any]) -> SlotTypes:
    """``slot_types`` over message classes by type name (``generate_dynamic``'s result, or
    installed classes)."""
    def slot_types(name: str) -> List[str]:
        cls = classes.get(name)
        if cls is None:
            raise LookupError(f"no definition of [{name}]")
        return list(cls._slot_types)
    return slot_types
