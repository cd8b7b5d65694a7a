"""Filling messages from YAML-parsed values: genpy's ``fill_message_args`` (the ROS YAML
command-line convention that ``rostopic pub``, ``rosservice call`` and tools built on genpy
use) and ``get_printable_message_args``.

A list fills fields positionally, one dict by name (nested dicts and lists fill embedded
messages and arrays), a string names a substitution key (``now``, ``auto``) for a message or
time field, and an integer for a time or duration is nanoseconds. The rules and error texts are
genpy's (checked against Debian's genpy on a generated corpus); values are not type-checked
here: serialization does that and names the bad field.
"""

from __future__ import annotations

from typing import Any, Dict, List, Sequence, Tuple

from minros.exceptions import MessageException

from .message import Message
from .spec import PRIMITIVE_TYPES
from .tval import Duration, Time, TVal

__all__ = ["fill_message_args", "get_printable_message_args", "printable_message_args",
           "substitution_keys", "parse_type"]

#: the fields of a time value (genpy's Time and Duration declare them as their __slots__)
_TVAL_FIELDS = ["secs", "nsecs"]


def parse_type(type_name: str) -> Tuple[str, bool, int | None]:
    """``'uint8[4]'`` -> ``('uint8', True, 4)``; ``'Foo[]'`` -> ``('Foo', True, None)``."""
    if type_name.endswith("]") and "[" in type_name:
        base, _, rest = type_name.partition("[")
        size = rest[:-1]
        return base, True, int(size) if size else None
    return type_name, False, None


def _fields(msg: Any) -> List[str]:
    return _TVAL_FIELDS if isinstance(msg, TVal) else list(msg.__slots__)


def _element_class(msg: Any, field: str, base_type: str) -> Any:
    """Class of the elements of a message array field, or None (works for dynamic classes:
    the embedded class is found through an instance when the array has one)."""
    if base_type == "time":
        return Time
    if base_type == "duration":
        return Duration
    module_classes = getattr(type(msg), "_field_classes", None)
    if isinstance(module_classes, dict) and field in module_classes:
        return module_classes[field]
    from .registry import UnknownTypeError, get_message_class, normalize_type

    try:
        return get_message_class(normalize_type(base_type))
    except (UnknownTypeError, ValueError):
        return None


def _time_from_nsecs(cls: type, nsecs: int) -> TVal:
    # genpy's (lossy) conversion through float seconds, kept so both fill alike
    return (Time if issubclass(cls, Time) else Duration).from_sec(nsecs / 1e9)


def _fill_value(msg: Any, field: Any, value: Any, keys: Dict[str, Any], prefix: str) -> None:
    if field not in _fields(msg):
        raise MessageException(f"No field name [{prefix}{field}]")
    current = getattr(msg, field)
    if isinstance(current, (Message, TVal)):
        if type(value) is str:
            if value not in keys:
                raise MessageException(f"No key named [{value}]")
            setattr(msg, field, keys[value])
        elif isinstance(current, TVal) and type(value) is int:
            setattr(msg, field, _time_from_nsecs(type(current), value))
        else:
            _fill(current, value, keys, prefix + field + ".")
        return
    if type(current) is not list:
        setattr(msg, field, value)  # checked when the message is serialized
        return
    if type(value) not in (list, tuple):
        raise MessageException(f"Field [{prefix}{field}] must be a list or tuple instead of: "
                               f"{type(value).__name__}")
    base, _is_array, length = parse_type(msg._slot_types[_fields(msg).index(field)])
    if length is not None and len(value) != length:
        raise MessageException(f"Field [{prefix}{field}] has incorrect number of elements: "
                               f"{len(value)} != {length}")
    if base in PRIMITIVE_TYPES:
        setattr(msg, field, value)
        return
    cls = _element_class(msg, field, base)
    if cls is None:
        raise MessageException(f"Cannot instantiate messages for field [{prefix}{field}] : "
                               f"cannot load class {base}")
    del current[:]
    for element in value:
        if issubclass(cls, TVal) and type(element) is int:
            item = _time_from_nsecs(cls, element)
        else:
            item = cls()
            _fill(item, element, keys, prefix)
        current.append(item)


def _fill(msg: Any, args: Any, keys: Dict[str, Any], prefix: str = "") -> None:
    if not isinstance(msg, (Message, TVal)):
        raise ValueError(f"msg must be a Message instance: {msg}")
    if type(args) is dict:
        for field, value in args.items():
            _fill_value(msg, field, "" if value is None else value, keys, prefix)
    elif type(args) is list:
        fields = _fields(msg)
        if len(args) > len(fields):
            raise MessageException(f"Too many arguments:\n * Given: {args}\n * Expected: {fields}")
        if len(args) < len(fields):
            raise MessageException(f"Not enough arguments:\n * Given: {args}\n * Expected: {fields}")
        for field, value in zip(fields, args):
            _fill_value(msg, field, value, keys, prefix)
    else:
        raise ValueError(f"invalid msg_args type: {args}")


def fill_message_args(msg: Any, msg_args: Sequence[Any] | None,
                      keys: Dict[str, Any] | None = None) -> None:
    """Fill ``msg`` from YAML-parsed command-line ``msg_args`` (genpy.fill_message_args).

    Raises :class:`MessageException` for a missing field, a wrong count or an unknown key,
    ``ValueError`` for arguments of the wrong shape.
    """
    keys = {} if keys is None else keys
    if msg_args is None:
        msg_args = []
    if len(msg_args) == 1 and type(msg_args[0]) is dict:
        _fill(msg, msg_args[0], keys)
    else:
        _fill(msg, msg_args, keys)


def substitution_keys(now: Time | None = None) -> Dict[str, Any]:
    """``now`` -> current time, ``auto`` -> a std_msgs/Header stamped now (rostopic pub's keys)."""
    from .registry import get_message_class

    if now is None:
        import time as _time

        now = Time.from_sec(_time.time())
    return {"now": now, "auto": get_message_class("std_msgs/Header")(stamp=now)}


def get_printable_message_args(msg: Any, buff: Any = None, prefix: str = "") -> str:
    """The fields a positional argument list fills, e.g. ``'header.seq header.stamp
    header.frame_id data'`` (genpy.message.get_printable_message_args); a class is accepted too.
    """
    parts: List[str] = []

    def walk(m: Any, pre: str) -> None:
        for field in m.__slots__:
            value = getattr(m, field)
            if isinstance(value, Message):
                walk(value, pre + field + ".")
            else:
                parts.append(pre + field)

    walk(msg() if isinstance(msg, type) else msg, prefix)
    text = " ".join(parts)
    if buff is not None:
        buff.write(text + " ")
    return text


#: the name minros's tools used for it
printable_message_args = get_printable_message_args

#: genpy.message's names of the two steps (code written for genpy calls them directly)
_fill_message_args = _fill
_fill_val = _fill_value
