"""The ``Message`` base class (genpy's contract) and the helpers generated code calls.

Generated classes (see :mod:`minros.msgs.codegen`) provide ``_serialize_parts(append)`` and
``_deserialize_from(view, offset) -> end``; this base turns them into genpy's public
``serialize(buff)`` / ``deserialize(data)`` with one clear error on bad data or values.
"""

from __future__ import annotations

import codecs
import struct
from typing import Any, Callable, Iterable, List

from minros.exceptions import DeserializationError, SerializationError

from .tval import Duration, Time, TVal

__all__ = [
    "Message", "strify_message", "check_type", "DeserializationError", "SerializationError",
    "struct_I", "isstring", "reader_for", "SERIALIZE_ERRORS",
]

#: the uint32 of every length prefix (genpy.struct_I: genpy-generated modules use it)
struct_I = struct.Struct("<I")


def isstring(s: Any) -> bool:
    """genpy.message.isstring: whether ``s`` is a ``str``."""
    return isinstance(s, str)


class RosMsgUnicodeErrors:
    """The ``'rosmsg'`` codec error handler genpy registers and its generated code decodes
    strings with: bytes that are not UTF-8 become U+FFFD, and the first time this happens for a
    message type (``msg_type``, which that code sets before decoding) an error is logged."""

    def __init__(self) -> None:
        self.msg_type: str | None = None
        self._warned: set = set()

    def __call__(self, err: UnicodeError) -> tuple:
        return self.report(self.msg_type, err)

    def report(self, msg_type: str | None, err: UnicodeError) -> tuple:
        """Log the first decoding error of ``msg_type`` (genpy's text), replace the bytes."""
        if msg_type not in self._warned:
            self._warned.add(msg_type)
            import logging

            what = f"message {msg_type}" if msg_type else "unknown message"
            logging.getLogger("rosout").error(
                "Characters replaced when decoding %s (will print only once): %s", what, err)
        return codecs.replace_errors(err)


_ROSMSG_ERRORS = RosMsgUnicodeErrors()
codecs.register_error("rosmsg", _ROSMSG_ERRORS)
_decoders: set = set()


def decoding_errors(type_name: str) -> str:
    """The codec error handler the strings of ``type_name`` decode with (minros's generated
    classes): ``'rosmsg'``'s rule with the type fixed, so no decode sets shared state first."""
    name = f"rosmsg:{type_name}"
    if name not in _decoders:
        codecs.register_error(name, lambda err: _ROSMSG_ERRORS.report(type_name, err))
        _decoders.add(name)
    return name

#: Largest element count accepted for arrays whose elements occupy no bytes on the wire
#: (e.g. ``std_msgs/Empty[]``): the count cannot be checked against the data, so bound it.
MAX_EMPTY_ELEMENTS = 1 << 20

_INT_WIDTHS = {
    "byte": (8, True), "int8": (8, True), "int16": (16, True), "int32": (32, True),
    "int64": (64, True), "char": (8, False), "uint8": (8, False), "uint16": (16, False),
    "uint32": (32, False), "uint64": (64, False),
}
#: what a serializer raises for a field of the wrong type or range
SERIALIZE_ERRORS = (struct.error, TypeError, ValueError, AttributeError, OverflowError,
                    UnicodeError, IndexError, SerializationError)
_SERIALIZE_ERRORS = SERIALIZE_ERRORS


def _as_view(data: Any, zero_copy: bool) -> Any:
    """What a deserializer reads ``data`` (not ``bytes``) from."""
    if zero_copy:
        # may hold a big array: read it in place, copy only the fields
        view = data if data.__class__ is memoryview else memoryview(data)
        if view.format != "B" or view.ndim != 1:
            view = view.cast("B")
        return view
    return bytes(data)  # small: one copy, then the faster bytes operations


def _truncated(type_name: str, view: Any) -> DeserializationError:
    return DeserializationError(
        f"{type_name}: message truncated ({len(view)} bytes do not hold a whole message)")


def _trailing(type_name: str, view: Any, end: int) -> DeserializationError:
    return DeserializationError(
        f"{type_name}: {len(view) - end} unexpected bytes after the message "
        f"({end} of {len(view)} bytes used)")


def reader_for(cls: Any, in_place: bool = False) -> Callable[[Any], Any]:
    """A function from serialized bytes to a new ``cls`` message: ``cls().deserialize(data)``,
    but for a generated class without first building default fields that the data replaces
    (a message with embedded messages reads 1.5-2x faster). Subscribers and bag readers
    take one per class.

    ``in_place``: variable-length ``uint8[]``/``char[]`` fields are slices of the data, so a
    memoryview's are views of it, valid as long as its memory is (the shared-memory transport
    reads its slots so)."""
    fresh = cls.__dict__.get("_deserialize_fresh")
    if (in_place and fresh is not None and cls._zero_copy and not cls._keeps_buffer
            and cls.__dict__.get("_context")):
        fresh = cls._context.get_in_place_class(cls).__dict__.get("_deserialize_fresh")
    if fresh is None or cls.deserialize is not Message.deserialize:
        def read_any(data: Any) -> Any:  # hand-written, subclassed or genpy-generated classes
            msg = cls()
            msg.deserialize(data)
            return msg
        return read_any
    zero_copy = cls._zero_copy
    type_name = cls._type
    new = object.__new__

    def read(data: Any) -> Any:
        view = data if data.__class__ is bytes else _as_view(data, zero_copy)
        msg = new(cls)
        try:
            end = fresh(msg, view, 0)
        except struct.error:
            raise _truncated(type_name, view) from None
        if end != len(view):
            raise _trailing(type_name, view, end)
        return msg
    return read


class Message:
    """Base class of all message classes (genpy.Message contract)."""

    __slots__ = ("_connection_header",)
    _type = ""
    _md5sum = ""
    _full_text = ""
    _has_header = False
    _zero_copy = True
    #: whether a deserialized message may keep references into the received bytes (numpy_msg
    #: views do); False lets a subscriber reuse one receive buffer for its big frames
    _keeps_buffer = True
    _slot_types: List[str] = []
    #: the message context (registry) the class came from; the registry sets the default for
    #: every class and its own for those it builds (numpy_msg finds the numpy variant there)
    _context: Any = None

    def __init__(self, *args: Any, **kwds: Any) -> None:
        # Generated classes override this; kept for hand-written subclasses.
        _init_fields(self, args, kwds)

    # -- genpy API ---------------------------------------------------------------------------
    def _get_types(self) -> List[str]:
        return self._slot_types

    def _check_types(self, exc: BaseException | None = None) -> None:
        """Type-check every field; raise :class:`SerializationError` naming the bad one, else
        (when given) one carrying ``exc``'s text, as genpy does."""
        for name, type_ in zip(self.__slots__, self._get_types()):
            check_type(name, type_, getattr(self, name))
        if exc is not None:
            raise SerializationError(str(exc))

    def serialize(self, buff: Any) -> None:
        """Write the wire form of this message to ``buff`` (anything with ``.write``).

        The pieces are written as they are produced, as genpy does (large arrays are handed
        over without being copied or joined); on a bad field value the error names the field,
        and ``buff`` may hold a partial message.
        """
        try:
            self._serialize_parts(buff.write)
        except _SERIALIZE_ERRORS as exc:
            raise _serialization_error(self, exc) from None
        except NotImplementedError:
            if type(self)._serialize_parts is not Message._serialize_parts:
                raise
            # genpy's base Message: a class without fields of its own writes nothing

    def serialize_to_bytes(self) -> bytes:
        """The wire form of this message as ``bytes``."""
        parts: List[Any] = []
        try:
            self._serialize_parts(parts.append)
            return b"".join(parts)
        except _SERIALIZE_ERRORS as exc:
            raise _serialization_error(self, exc) from None

    def deserialize(self, data: Any) -> Message | None:
        """Fill this message from ``data`` (bytes, bytearray, memoryview); returns self (None
        for genpy's base Message, which has nothing to read).

        The data must hold exactly one message: truncated data, lengths pointing past the end
        and trailing bytes raise :class:`DeserializationError`.
        """
        view = data
        if data.__class__ is not bytes:
            try:
                view = _as_view(data, self._zero_copy)
            except TypeError:
                if type(self)._deserialize_from is Message._deserialize_from:
                    return None  # genpy's base Message reads nothing, whatever it is given
                raise
        try:
            try:
                end = self._deserialize_from(view, 0)
            except AttributeError:
                # made without its constructor (cls.__new__): give it default fields first
                self.__class__.__init__(self)
                end = self._deserialize_from(view, 0)
        except NotImplementedError:
            if type(self)._deserialize_from is not Message._deserialize_from:
                raise
            return None  # genpy's base Message reads nothing
        except struct.error:
            raise _truncated(self._type, view) from None
        if end != len(view):
            raise _trailing(self._type, view, end)
        return self

    # genpy's numpy variants (rospy.numpy_msg and rosbag call these)
    def serialize_numpy(self, buff: Any, numpy: Any = None) -> None:
        """As :meth:`serialize`; numpy arrays in fields are accepted by every class."""
        self.serialize(buff)

    def deserialize_numpy(self, data: Any, numpy: Any = None) -> Message:
        """As :meth:`deserialize`, but numeric arrays become numpy views of ``data``."""
        view = data if data.__class__ is memoryview else memoryview(data)
        if view.format != "B" or view.ndim != 1:
            view = view.cast("B")
        # the numpy variant's reader fills any instance of the type (it sets fields by name)
        reader = type(self)._context.get_numpy_class(type(self))._deserialize_from
        try:
            try:
                end = reader(self, view, 0)
            except AttributeError:
                self.__class__.__init__(self)
                end = reader(self, view, 0)
        except struct.error:
            raise DeserializationError(f"{self._type}: message truncated") from None
        if end != len(view):
            raise DeserializationError(f"{self._type}: {len(view) - end} unexpected bytes after the message")
        return self

    def _serialize_parts(self, append: Callable[[Any], None]) -> None:  # pragma: no cover
        raise NotImplementedError

    def _deserialize_from(self, view: memoryview, end: int) -> int:  # pragma: no cover
        raise NotImplementedError

    # -- Python protocol ---------------------------------------------------------------------
    def __getstate__(self) -> list:
        return [getattr(self, name) for name in self.__slots__]

    def __setstate__(self, state: list) -> None:
        for name, value in zip(self.__slots__, state):
            setattr(self, name, value)

    def __repr__(self) -> str:
        return strify_message(self)

    def __str__(self) -> str:
        return strify_message(self)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, self.__class__) and not isinstance(self, other.__class__):
            return False
        if getattr(other, "_type", None) != self._type:
            return False
        for name in self.__slots__:
            try:
                if not _values_equal(getattr(self, name), getattr(other, name)):
                    return False
            except AttributeError:
                return False
        return True

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]  # mutable, like genpy messages


def _values_equal(a: Any, b: Any) -> bool:
    if type(a) in (list, tuple) and type(b) in (list, tuple):
        return len(a) == len(b) and all(_values_equal(x, y) for x, y in zip(a, b))
    if hasattr(a, "__array__") or hasattr(b, "__array__"):
        import numpy

        return bool(numpy.array_equal(numpy.asarray(a), numpy.asarray(b)))
    return bool(a == b)


def _init_fields(msg: Message, args: tuple, kwds: dict) -> None:
    """genpy's constructor rules: all fields positionally, or any subset by keyword."""
    slots = msg.__slots__
    if args and kwds:
        raise TypeError("Message constructor may only use args OR keywords, not both")
    if args:
        if len(args) != len(slots):
            raise TypeError(f"Invalid number of arguments, args should be {list(slots)} args are {args}")
        for name, value in zip(slots, args):
            setattr(msg, name, value)
        return
    for key in kwds:
        if key not in slots:
            raise AttributeError(f"{key} is not an attribute of {type(msg).__name__}")
    for name in slots:
        setattr(msg, name, kwds.get(name))


# ---------------------------------------------------------------------------------------------
# type checking (genpy.message.check_type: diagnosis of serialization failures)

#: numpy scalar types genpy accepts for a float field (besides float and int)
_NUMPY_NUMBER_TYPES = {"float32", "float64", "int8", "int16", "int32", "int64", "uint8",
                       "uint16", "uint32", "uint64"}
_SIMPLE_TYPES = frozenset(_INT_WIDTHS) | {"float32", "float64", "bool"}


def _is_float_value(value: Any) -> bool:
    cls = type(value)
    if cls is float or cls is int:
        return True
    return cls.__module__ == "numpy" and cls.__name__ in _NUMPY_NUMBER_TYPES


def check_type(field_name: str, field_type: str, field_val: Any) -> None:
    """Raise :class:`SerializationError` if ``field_val`` cannot be written as ``field_type``.

    genpy's rules and texts (its generated code calls this after a failed serialization to
    name the bad field): integers must be ``int`` within the type's width, floats Python or
    numpy numbers, strings ASCII ``str`` or ``bytes``, ``uint8[]``/``char[]`` may be ``bytes``
    or ``str``, other arrays lists or tuples, embedded messages of the declared type.
    """
    if field_type in _SIMPLE_TYPES:
        if field_type in _INT_WIDTHS:
            bits, signed = _INT_WIDTHS[field_type]
            if signed:
                if type(field_val) is not int:
                    raise SerializationError(f"field {field_name} must be an integer type")
                if not -(1 << (bits - 1)) <= field_val < (1 << (bits - 1)):
                    raise SerializationError(
                        f"field {field_name} exceeds specified width [{field_type}]")
            else:
                if type(field_val) is not int or field_val < 0:
                    raise SerializationError(f"field {field_name} must be unsigned integer type")
                if field_val >= (1 << bits):
                    raise SerializationError(
                        f"field {field_name} exceeds specified width [{field_type}]")
        elif field_type == "bool":
            if field_val not in (True, False, 0, 1):
                raise SerializationError(f"field {field_name} is not a bool")
        elif not _is_float_value(field_val):
            raise SerializationError(f"field {field_name} must be float type")
    elif field_type == "string":
        if type(field_val) is str:
            if not field_val.isascii():
                raise SerializationError(f"field {field_name} is a non-ascii string")
        elif type(field_val) is not bytes:
            raise SerializationError(
                f"field {field_name} must be of type bytes or an ascii string")
    elif field_type == "time":
        if not isinstance(field_val, Time):
            raise SerializationError(f"field {field_name} must be of type Time")
    elif field_type == "duration":
        if not isinstance(field_val, Duration):
            raise SerializationError(f"field {field_name} must be of type Duration")
    elif field_type.endswith("]"):
        base_type = field_type[:field_type.index("[")]
        if type(field_val) in (bytes, str):
            if base_type not in ("char", "uint8"):
                raise SerializationError(f"field {field_name} must be a list or tuple type. "
                                         "Only uint8[] can be a string")
            return
        if type(field_val) not in (list, tuple):
            raise SerializationError(f"field {field_name} must be a list or tuple type")
        for item in field_val:
            check_type(field_name + "[]", base_type, item)
    elif isinstance(field_val, Message):
        if field_val._type in ("std_msgs/Header", "roslib/Header"):
            if field_type not in ("Header", "std_msgs/Header", "roslib/Header"):
                raise SerializationError(
                    f"field {field_name} must be a Header instead of a {field_val._type}")
        elif field_val._type != field_type:
            raise SerializationError(
                f"field {field_name} must be of type {field_type} instead of {field_val._type}")
        for name, type_ in zip(field_val.__slots__, field_val._get_types()):
            check_type(f"{field_name}.{name}", type_, getattr(field_val, name))
    else:
        raise SerializationError(f"field {field_name} must be of type [{field_type}]")


def _serialization_error(msg: Message, exc: BaseException) -> SerializationError:
    """What genpy's generated code raises when writing fails: check_type's diagnosis of the
    first bad field, else the underlying error's text."""
    try:
        msg._check_types()
    except SerializationError as found:
        return found
    if isinstance(exc, SerializationError):
        return exc
    try:
        shown = str(msg)
    except Exception:  # noqa: BLE001 - a field too broken to print
        shown = msg._type
    return SerializationError(f"{type(exc)}: '{exc}' when writing '{shown}'")


# ---------------------------------------------------------------------------------------------
# YAML-like text (genpy.strify_message)

def _yaml_quote(text: str) -> str:
    import yaml  # only when printing: keeps message import fast

    return yaml.dump(text, default_style='"').rstrip("\n")


def strify_message(val: Any, indent: str = "", time_offset: Time | None = None,
                   current_time: Time | None = None, field_filter: Callable | None = None,
                   fixed_numeric_width: int | None = None) -> str:
    """YAML-like text of a message or value, formatted exactly as genpy does."""
    type_ = type(val)
    if type_ in (int, float) and fixed_numeric_width is not None:
        if type_ is float:
            num_str = ("%." + str(fixed_numeric_width) + "f") % val
            return num_str[:max(num_str.find("."), fixed_numeric_width)]
        return ("%" + str(fixed_numeric_width) + "d") % val
    if type_ in (int, float, bool):
        return str(val)
    if isinstance(val, str):
        if not val:
            return "''"
        return _yaml_quote(val)
    if isinstance(val, TVal):
        if time_offset is not None and isinstance(val, Time):
            val = val - time_offset
        if fixed_numeric_width is not None:
            fmt = "%" + str(fixed_numeric_width) + "d"
            return f"\n{indent}secs: " + (fmt % val.secs) + f"\n{indent}nsecs: " + (fmt % val.nsecs)
        return f"\n{indent}secs: {val.secs}\n{indent}nsecs: {val.nsecs:9d}"
    if type_ in (list, tuple):
        if len(val) == 0:
            return "[]"
        val0 = val[0]
        if type(val0) in (int, float) and fixed_numeric_width is not None:
            return "[" + ", ".join(strify_message(v, indent, time_offset, current_time, field_filter,
                                                   fixed_numeric_width) for v in val) + "]"
        if isinstance(val0, str):
            import yaml

            text = yaml.dump(list(val)).rstrip("\n")
            if text[0] == "[":
                return text
            return "\n" + "\n".join(indent + line for line in text.splitlines())
        if type(val0) in (int, float, bool):
            return str(list(val))
        pref = indent + "- "
        indent = indent + "  "
        return "\n" + "\n".join(pref + strify_message(v, indent, time_offset, current_time,
                                                      field_filter, fixed_numeric_width) for v in val)
    if isinstance(val, Message):
        fields: Iterable[str] = list(field_filter(val)) if field_filter is not None else val.__slots__
        sub_indent = "  " + indent
        lines = [
            "{}{}: {}".format(indent, name, strify_message(_convert_getattr(val, name, type_name), sub_indent,
                                                      time_offset, current_time, field_filter,
                                                      fixed_numeric_width))
            for name, type_name in zip(val.__slots__, val._slot_types) if name in fields
        ]
        text = "\n".join(lines)
        return "\n" + text if indent else text
    if hasattr(val, "__array_interface__") and hasattr(val, "tolist"):
        return strify_message(val.tolist(), indent, time_offset, current_time, field_filter,
                              fixed_numeric_width)
    return str(val)


def _convert_getattr(msg: Message, name: str, type_name: str) -> Any:
    value = getattr(msg, name)
    if "uint8[" in type_name and isinstance(value, (bytes, bytearray, memoryview)):
        return list(bytes(value))
    if "uint8[" in type_name and isinstance(value, str):
        return [ord(c) for c in value]
    return value
