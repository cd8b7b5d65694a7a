"""The CBOR encoding rosbridge sends for ``compression: "cbor"`` and ``"cbor-raw"``.

Only what the server sends is here (RFC 8949 major types 0-7 for the values a message can
hold, plus the little-endian typed-array tags of RFC 8746 that rosbridge uses for numeric
arrays); clients never send CBOR to a ROS 1 rosbridge. A few dozen lines did not justify a
dependency.

``message_to_cbor_values(msg)`` applies rosbridge's cbor_conversion rules: ``uint8[]``/``char[]``
as a byte string, numeric arrays as tagged little-endian byte strings, time as ``{secs, nsecs}``.
"""

from __future__ import annotations

import struct
from typing import Any, Callable, Dict, List, Tuple

from minros.web.convert import FLOATS, INTS, TIME_TYPES, split_array


class Tag:
    """A tagged CBOR value (typed arrays)."""

    __slots__ = ("tag", "value")

    def __init__(self, tag: int, value: Any) -> None:
        self.tag = tag
        self.value = value

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Tag) and (self.tag, self.value) == (other.tag, other.value)

    def __repr__(self) -> str:
        return f"Tag({self.tag}, {self.value!r})"


def _head(major: int, value: int) -> bytes:
    if value < 24:
        return bytes((major << 5 | value,))
    if value < 0x100:
        return bytes((major << 5 | 24, value))
    if value < 0x10000:
        return bytes((major << 5 | 25,)) + struct.pack(">H", value)
    if value < 0x100000000:
        return bytes((major << 5 | 26,)) + struct.pack(">I", value)
    return bytes((major << 5 | 27,)) + struct.pack(">Q", value)


def _encode(value: Any, out: List[bytes]) -> None:
    kind = type(value)
    if kind is str:
        data = value.encode("utf-8")
        out.append(_head(3, len(data)))
        out.append(data)
    elif kind is bool:
        out.append(b"\xf5" if value else b"\xf4")
    elif kind is int:
        if value >= 0:
            out.append(_head(0, value))
        else:
            out.append(_head(1, -1 - value))
    elif kind is float:
        out.append(b"\xfb" + struct.pack(">d", value))
    elif value is None:
        out.append(b"\xf6")
    elif kind is dict:
        out.append(_head(5, len(value)))
        for key, item in value.items():
            _encode(key, out)
            _encode(item, out)
    elif kind in (list, tuple):
        out.append(_head(4, len(value)))
        for item in value:
            _encode(item, out)
    elif kind in (bytes, bytearray, memoryview):
        out.append(_head(2, len(value)))
        out.append(bytes(value) if kind is not bytes else value)
    elif kind is Tag:
        out.append(_head(6, value.tag))
        _encode(value.value, out)
    elif hasattr(value, "__index__"):  # numpy integers
        _encode(int(value), out)
    elif hasattr(value, "__float__"):  # numpy floats
        _encode(float(value), out)
    else:
        raise TypeError(f"cannot encode {kind.__name__} as CBOR")


def dumps(value: Any) -> bytes:
    """CBOR bytes of ``value`` (dict, list, str, bytes, int, float, bool, None, Tag)."""
    out: List[bytes] = []
    _encode(value, out)
    return b"".join(out)


#: element type -> (RFC 8746 little-endian tag, struct code)
TYPED_ARRAYS: Dict[str, Tuple[int, str]] = {
    "uint16": (69, "H"), "uint32": (70, "I"), "uint64": (71, "Q"),
    "byte": (72, "b"), "int8": (72, "b"), "int16": (77, "h"), "int32": (78, "i"),
    "int64": (79, "q"), "float32": (85, "f"), "float64": (86, "d"),
}


def _typed(tag: int, code: str) -> Callable[[Any], Tag]:
    def pack(values: Any) -> Tag:
        return Tag(tag, struct.pack(f"<{len(values)}{code}", *values))
    return pack


def _cbor_field(slot_type: str) -> Callable[[Any], Any]:
    base, array = split_array(slot_type)
    if array:
        if base in ("uint8", "char"):
            return bytes
        if base in TYPED_ARRAYS:
            return _typed(*TYPED_ARRAYS[base])
        if base == "bool":
            return lambda v: [bool(x) for x in v]
        if base == "string":
            return lambda v: [str(x) for x in v]
        if base in TIME_TYPES:
            return lambda v: [{"secs": int(t.secs), "nsecs": int(t.nsecs)} for t in v]
        return lambda v: [message_to_cbor_values(x) for x in v]
    if base == "string":
        return str
    if base == "bool":
        return bool
    if base in INTS:
        return int
    if base in FLOATS:
        return float
    if base in TIME_TYPES:
        return lambda t: {"secs": int(t.secs), "nsecs": int(t.nsecs)}
    return message_to_cbor_values


_PLANS: Dict[type, List[Tuple[str, Callable[[Any], Any]]]] = {}


def message_to_cbor_values(msg: Any) -> Dict[str, Any]:
    """The values rosbridge puts in a CBOR ``publish`` for ``msg``."""
    cls = type(msg)
    plan = _PLANS.get(cls)
    if plan is None:
        plan = [(name, _cbor_field(t)) for name, t in zip(cls.__slots__, cls._slot_types)]
        _PLANS[cls] = plan
    return {name: convert(getattr(msg, name)) for name, convert in plan}
