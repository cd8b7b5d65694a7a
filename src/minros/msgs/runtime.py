"""Names the generated message code uses (imported by every generated module).

Kept small and explicit so the printed source of a message class (``minros msg gen``) reads
like ordinary Python and runs on its own: it imports by name the few of :data:`EXPORTS` it
uses, each under an alias prefixed with ``_`` so it never clashes with a message named ``Time``
or ``Struct`` (``from minros.msgs.runtime import Message as _Message, ...``).
"""

from __future__ import annotations

import struct
from struct import Struct
from typing import Any, Callable

from minros.exceptions import DeserializationError, SerializationError

from .message import MAX_EMPTY_ELEMENTS, Message, _init_fields, decoding_errors, struct_I
from .tval import Duration, Time

#: genpy's constructor rules (all fields positionally, or any by keyword)
init_fields = _init_fields

#: ``new(Cls)`` makes an instance without running ``__init__`` (deserialization fills it).
new = object.__new__
#: the uint32 used for every length and count prefix
S_I = struct_I

_ITEM_SIZE = {"b": 1, "B": 1, "?": 1, "h": 2, "H": 2, "i": 4, "I": 4, "q": 8, "Q": 8,
              "f": 4, "d": 8}
_NUMPY_DTYPE = {"b": "<i1", "B": "<u1", "?": "bool", "h": "<i2", "H": "<u2", "i": "<i4",
                "I": "<u4", "q": "<i8", "Q": "<u8", "f": "<f4", "d": "<f8"}


def overrun(type_: str, field: str, need: int, have: int) -> DeserializationError:
    """The error for a length field that points past the end of the data."""
    return DeserializationError(
        f"{type_}: field {field} needs {need} bytes but only {have} remain (truncated data "
        f"or a bad length)")


def too_many(type_: str, field: str, count: int, have: int) -> DeserializationError:
    """The error for an element count the remaining data cannot hold."""
    return DeserializationError(
        f"{type_}: field {field} claims {count} elements but only {have} bytes remain")


def bad_length(field: str, want: int, got: int) -> SerializationError:
    return SerializationError(f"field {field} must have exactly {want} elements, not {got}")


def _numpy_bytes(code: str, value: Any) -> memoryview:
    """A numpy array (or other sequence) as the wire bytes of a numeric array field.

    Values are converted to the field's type only when that loses nothing a reader would
    notice: floats never become integers, integers must fit the field's range.
    """
    import numpy

    array = numpy.asarray(value)
    target = numpy.dtype(_NUMPY_DTYPE[code])
    if array.dtype != target:
        if array.dtype.kind not in "biuf":
            raise TypeError(f"a {target} array field cannot hold values of type {array.dtype}")
        if target.kind in "iu":
            if array.dtype.kind == "f":
                raise TypeError(f"an integer array field cannot hold {array.dtype} values")
            info = numpy.iinfo(target)
            if array.size and (array.min() < info.min or array.max() > info.max):
                raise ValueError(f"values outside the range of {target}")
    array = numpy.ascontiguousarray(array, dtype=target).reshape(-1)
    return array.data.cast("B")


def put_array(append: Callable[[Any], None], code: str, value: Any) -> None:
    """Append a variable-length numeric array: uint32 count, then the items."""
    if value.__class__ is list or value.__class__ is tuple:
        count = len(value)
        append(S_I.pack(count))
        append(struct.pack(f"<{count}{code}", *value))
        return
    if isinstance(value, (str, bytes, bytearray)):
        raise TypeError(f"expected a sequence of numbers, got {type(value).__name__}")
    data = _numpy_bytes(code, value)
    append(S_I.pack(len(data) // _ITEM_SIZE[code]))
    append(data)


def as_bytes(value: Any) -> Any:
    """A ``uint8[]`` value (bytes, list of ints, numpy array, ...) as a bytes-like object."""
    cls = value.__class__
    if cls is bytes or cls is bytearray:
        return value
    if cls is list or cls is tuple:
        return bytes(value)
    if cls is str:  # genpy (py2 heritage) accepts a str of latin-1 characters
        return value.encode("latin-1")
    if hasattr(value, "__array_interface__"):
        return _numpy_uint8(value)
    view = memoryview(value)
    return view if view.format == "B" and view.ndim == 1 else view.cast("B")


def _numpy_uint8(value: Any) -> memoryview:
    """A numpy array for a ``uint8[]`` field: 1-byte items as they are, wider ones converted
    (values must fit 0..255), always C-contiguous."""
    import numpy

    array = numpy.asarray(value)
    if array.dtype.itemsize != 1 or array.dtype.kind not in "iub":
        if array.dtype.kind not in "iu":
            raise TypeError(f"a uint8[] field cannot hold a numpy array of {array.dtype}")
        if array.size and (array.min() < 0 or array.max() > 255):
            raise ValueError("a uint8[] field holds values outside 0..255")
        array = array.astype(numpy.uint8)
    return numpy.ascontiguousarray(array).reshape(-1).data.cast("B")


def unpack_array(code: str, count: int, view: memoryview, offset: int) -> tuple:
    """Unpack ``count`` numeric items (the caller checked the size)."""
    return struct.unpack_from(f"<{count}{code}", view, offset)


def numpy_view(code: str, count: int, view: memoryview, offset: int) -> Any:
    """A numpy array over the received bytes (no copy), for ``numpy_msg`` classes."""
    import numpy

    return numpy.frombuffer(view, dtype=_NUMPY_DTYPE[code], count=count, offset=offset)


def as_list(value: Any, length: int, field: str) -> list:
    """A fixed-length array value that is not a list/tuple (e.g. a numpy array) as a list."""
    if isinstance(value, (str, bytes, bytearray)) or not hasattr(value, "__iter__"):
        raise TypeError(f"field {field} must be a sequence, not {type(value).__name__}")
    return list(value)


def string_bytes(value: Any) -> bytes:
    """A ``string`` field value that is not a ``str``: bytes-like objects are written as is."""
    if isinstance(value, (bytes, bytearray)):
        return bytes(value)
    raise TypeError(f"a string field must be str or bytes, not {type(value).__name__}")


#: the names generated code imports from this module: the alias it uses -> the name here
EXPORTS = {
    "_Struct": "Struct", "_Message": "Message", "_Time": "Time", "_Duration": "Duration",
    "_new": "new", "_S_I": "S_I", "_overrun": "overrun", "_too_many": "too_many",
    "_bad_length": "bad_length", "_put_array": "put_array", "_unpack_array": "unpack_array",
    "_numpy_view": "numpy_view", "_as_bytes": "as_bytes", "_as_list": "as_list",
    "_string_bytes": "string_bytes", "_init_fields": "init_fields",
    "_MAX_EMPTY_ELEMENTS": "MAX_EMPTY_ELEMENTS", "_decoding_errors": "decoding_errors",
}
__all__ = ["Duration", "MAX_EMPTY_ELEMENTS", "Message", "S_I", "Struct", "Time", "as_bytes", "as_list",
           "bad_length", "decoding_errors", "init_fields", "new", "numpy_view", "overrun", "put_array", "string_bytes",
           "too_many", "unpack_array"]
