"""Names the generated CDR code uses (see :mod:`.cdr`); small so printed codecs read well.

Generated modules import what they use from here under ``_``-prefixed aliases (``EXPORTS``).
"""

from __future__ import annotations

import struct
import sys
from array import array
from struct import Struct
from typing import Any, Iterable, List, Tuple

from minros.exceptions import DeserializationError, SerializationError

#: the encapsulation header of plain CDR, little endian (XCDR1 CDR_LE, options 0)
CDR_LE_HEADER = b"\x00\x01\x00\x00"
S_I = Struct("<I")
#: zero bytes for padding, by count
ZEROS = tuple(bytes(n) for n in range(8))
BIG_ENDIAN = sys.byteorder == "big"
new = object.__new__

_ITEM_SIZE = {"b": 1, "B": 1, "?": 1, "h": 2, "H": 2, "i": 4, "I": 4, "q": 8, "Q": 8,
              "f": 4, "d": 8}
_NUMPY_DTYPE = {"b": "<i1", "B": "<u1", "?": "bool", "h": "<i2", "H": "<u2", "i": "<i4",
                "I": "<u4", "q": "<i8", "Q": "<u8", "f": "<f4", "d": "<f8"}
#: array.array type codes per struct code (``l``/``L`` are 8 bytes on LP64 but not on Windows)
_ARRAY_CODE = {"b": "b", "B": "B", "h": "h", "H": "H", "i": "i", "I": "I", "q": "q", "Q": "Q",
               "f": "f", "d": "d"}


class Struct2:
    """Base of the generated ROS 2 message classes: equality by fields, a readable repr."""

    __slots__ = ()
    _type = ""

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        slots: Tuple[str, ...] = self.__slots__
        return all(getattr(self, s) == getattr(other, s) for s in slots)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        slots: Tuple[str, ...] = self.__slots__
        inner = ", ".join(f"{s}={getattr(self, s)!r}" for s in slots)
        return f"{self._type.replace('/', '.')}({inner})"


def overrun(type_: str, field: str, need: int, have: int) -> DeserializationError:
    return DeserializationError(
        f"{type_}: field {field} needs {need} bytes but only {have} remain (truncated CDR data "
        f"or a bad length)")


def too_many(type_: str, field: str, count: int, have: int) -> DeserializationError:
    return DeserializationError(
        f"{type_}: field {field} claims {count} elements but only {have} bytes remain")


def over_bound(type_: str, field: str, count: int, bound: int) -> DeserializationError:
    return DeserializationError(
        f"{type_}: field {field} has {count} elements (or characters), more than its bound "
        f"of {bound}")


def bad_length(type_: str, field: str, want: int, got: int, bounded: bool = False
               ) -> SerializationError:
    if bounded:
        return SerializationError(f"{type_}: field {field} may have at most {want} elements "
                                  f"(or characters), not {got}")
    return SerializationError(f"{type_}: field {field} must have exactly {want} elements, "
                              f"not {got}")


def encode_string(value: Any) -> bytes:
    """A string field's value as UTF-8 bytes (bytes are taken as they are)."""
    if value.__class__ is str:
        return bytes(value.encode())
    if isinstance(value, (bytes, bytearray, memoryview)):
        return bytes(value)
    raise TypeError(f"a string field must be str or bytes, not {type(value).__name__}")


def encode_wstring(value: Any) -> Tuple[int, bytes]:
    """A wstring as rmw_fastrtps writes it: the count of UTF-16 code units, each as a uint32."""
    if not isinstance(value, str):
        raise TypeError(f"a wstring field must be str, not {type(value).__name__}")
    units = array("H", value.encode("utf-16-le"))
    if BIG_ENDIAN:
        units.byteswap()
    wide = array("I", units)
    if BIG_ENDIAN:
        wide.byteswap()
    return len(units), wide.tobytes()


def decode_wstring(view: Any, offset: int, count: int) -> str:
    wide = array("I")
    wide.frombytes(view[offset:offset + 4 * count])
    if BIG_ENDIAN:
        wide.byteswap()
    try:
        units = array("H", wide)
    except OverflowError:
        raise DeserializationError("a wstring holds a code unit beyond 16 bits") from None
    if BIG_ENDIAN:
        units.byteswap()
    return units.tobytes().decode("utf-16-le", "replace")


def as_octets(value: Any) -> Any:
    """A ``uint8``/``byte``/``char`` array value (bytes, list of ints, numpy array, ...) as a
    bytes-like object of 1-byte items."""
    cls = value.__class__
    if cls is bytes or cls is bytearray:
        return value
    if cls is list or cls is tuple:
        if value and value[0].__class__ is bytes:  # rclpy's byte[]: a list of 1-byte bytes
            return b"".join(value)
        return bytes(value)
    if cls is str:
        raise TypeError("a uint8/byte array field cannot hold a str: encode it to bytes")
    if hasattr(value, "__array_interface__"):
        import numpy

        data = numpy.ascontiguousarray(value)
        if data.dtype.itemsize != 1:
            if data.size and (data.min() < 0 or data.max() > 255):
                raise ValueError("a uint8/byte array holds values outside 0..255")
            data = data.astype(numpy.uint8)
        return data.reshape(-1).data.cast("B")
    view = memoryview(value)
    return view if view.format in ("B", "b", "c") and view.ndim == 1 else view.cast("B")


def byte_value(value: Any) -> int:
    """A scalar ``byte`` (octet): an int 0..255, or rclpy's 1-byte ``bytes``."""
    if value.__class__ is bytes and len(value) == 1:
        return int(value[0])
    return value  # type: ignore[no-any-return]


def pack_numbers(code: str, value: Any) -> Any:
    """The little-endian bytes of a numeric array value (list, tuple, array.array, numpy)."""
    cls = value.__class__
    if cls is array and value.typecode == _ARRAY_CODE.get(code) and not BIG_ENDIAN:
        return memoryview(value).cast("B")
    if cls is list or cls is tuple:
        return struct.pack(f"<{len(value)}{code}", *value)
    if isinstance(value, (str, bytes, bytearray)):
        raise TypeError(f"expected a sequence of numbers, got {type(value).__name__}")
    if cls is array:
        return struct.pack(f"<{len(value)}{code}", *value)
    import numpy

    data = numpy.asarray(value)
    target = numpy.dtype(_NUMPY_DTYPE[code])
    if data.dtype != target:
        if data.dtype.kind not in "biuf":
            raise TypeError(f"a {target} array cannot hold values of type {data.dtype}")
        if target.kind in "iu" and data.dtype.kind == "f":
            raise TypeError(f"an integer array cannot hold {data.dtype} values")
        if target.kind in "iu" and data.size:
            info = numpy.iinfo(target)
            if data.min() < info.min or data.max() > info.max:
                raise ValueError(f"values outside the range of {target}")
    return numpy.ascontiguousarray(data, dtype=target).reshape(-1).data.cast("B")


def count_of(value: Any) -> int:
    return len(value)


def numbers(code: str, view: Any, offset: int, count: int) -> array[Any]:
    """``count`` little-endian numbers of struct code ``code`` as an ``array.array`` (one copy,
    no Python loop)."""
    out = array(_ARRAY_CODE[code])
    out.frombytes(view[offset:offset + count * _ITEM_SIZE[code]])
    if BIG_ENDIAN:
        out.byteswap()
    return out


def bools(view: Any, offset: int, count: int) -> List[bool]:
    return list(map(bool, bytes(view[offset:offset + count])))


def pack_bools(value: Iterable[Any]) -> bytes:
    if isinstance(value, (bytes, bytearray)):
        return bytes(1 if b else 0 for b in value)
    items = list(value)
    return struct.pack(f"{len(items)}?", *items)


def new_array(code: str, items: Iterable[Any] = ()) -> array[Any]:
    return array(_ARRAY_CODE[code], items)


#: the names generated code imports from this module: its alias -> the name here
EXPORTS = {
    "_Struct": "Struct", "_Struct2": "Struct2", "_new": "new", "_S_I": "S_I", "_ZEROS": "ZEROS",
    "_HEADER": "CDR_LE_HEADER", "_overrun": "overrun", "_too_many": "too_many",
    "_over_bound": "over_bound", "_bad_length": "bad_length", "_encode_string": "encode_string",
    "_encode_wstring": "encode_wstring", "_decode_wstring": "decode_wstring",
    "_as_octets": "as_octets", "_byte_value": "byte_value", "_pack_numbers": "pack_numbers",
    "_numbers": "numbers", "_bools": "bools", "_pack_bools": "pack_bools",
    "_new_array": "new_array", "_SerializationError": "SerializationError",
    "_DeserializationError": "DeserializationError",
}
