"""Fill messages from command-line YAML (the ROS YAML command-line convention, as genpy's
``fill_message_args``): a list fills fields positionally, a single dict fills by name,
``now``/``auto`` substitute the current time / a Header stamped now, integers become times
in nanoseconds."""

from __future__ import annotations

from typing import Any, Dict, List, Tuple

from minros.exceptions import MessageException
from minros.msgs import Duration, Message, Time, TVal, get_message_class

_PRIMITIVES = {"bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32",
               "int64", "uint64", "float32", "float64", "string", "time", "duration"}


def parse_type(type_name: str) -> Tuple[str, bool, int | None]:
    """``'uint8[4]'`` -> ``('uint8', True, 4)``; ``'Foo[]'`` -> ``('Foo', True, None)``."""
    if type_name.endswith("]") and "[" in type_name:
        base, _, rest = type_name.partition("[")
        size = rest[:-1]
        return base, True, int(size) if size else None
    return type_name, False, None


def _element_class(msg: Any, field: str, base_type: str) -> Any:
    """Class of the elements of a message array field (works for dynamic classes too)."""
    if base_type == "time":
        return Time
    if base_type == "duration":
        return Duration
    module_classes = getattr(type(msg), "_field_classes", None)
    if isinstance(module_classes, dict) and field in module_classes:
        return module_classes[field]
    if "/" not in base_type and base_type == "Header":
        base_type = "std_msgs/Header"
    return get_message_class(base_type)


def _fill_value(msg: Any, field: str, value: Any, keys: Dict[str, Any], prefix: str) -> None:
    if field not in msg.__slots__:
        raise MessageException(f"No field name [{prefix}{field}]")
    current = getattr(msg, field)
    if isinstance(current, (Message, TVal)):
        if isinstance(value, str):
            if value not in keys:
                raise MessageException(f"No key named [{value}]")
            sub = keys[value]
            if isinstance(current, Message) and type(sub).__name__ == "Header" and getattr(current, "_type", "") != "std_msgs/Header":
                raise MessageException(f"No key named [{value}]")
            if isinstance(current, TVal) and not isinstance(sub, TVal):
                raise MessageException(f"No key named [{value}]")
            if isinstance(current, Message) and not isinstance(sub, Message):
                raise MessageException(f"No key named [{value}]")
            if isinstance(current, Duration) and isinstance(sub, Time):
                sub = Duration(sub.secs, sub.nsecs)
            setattr(msg, field, sub)
        elif isinstance(current, TVal) and type(value) is int:
            setattr(msg, field, type(current).from_sec(value / 1e9) if isinstance(current, Time)
                    else Duration.from_sec(value / 1e9))
        else:
            _fill(current, value, keys, prefix + field + ".")
        return
    index = msg.__slots__.index(field)
    base, is_array, length = parse_type(msg._slot_types[index])
    if is_array and not (isinstance(current, (bytes, bytearray)) and isinstance(value, (bytes, str))):
        if not isinstance(value, (list, tuple)):
            raise MessageException(f"Field [{prefix}{field}] must be a list or tuple instead of: "
                                   f"{type(value).__name__}")
        if length is not None and len(value) != length:
            raise MessageException(f"Field [{prefix}{field}] has incorrect number of elements: "
                                   f"{len(value)} != {length}")
        if base in _PRIMITIVES and base not in ("time", "duration"):
            setattr(msg, field, list(value))
            return
        cls = _element_class(msg, field, base)
        items = []
        for element in value:
            if cls in (Time, Duration) and type(element) is int:
                items.append(cls.from_sec(element / 1e9))
                continue
            item = cls()
            _fill(item, element, keys, prefix)
            items.append(item)
        setattr(msg, field, items)
        return
    setattr(msg, field, value)


def _fill(msg: Any, args: Any, keys: Dict[str, Any], prefix: str = "") -> None:
    if not isinstance(msg, (Message, TVal)):
        raise MessageException(f"msg must be a Message instance: {msg}")
    if isinstance(args, dict):
        for field, value in args.items():
            _fill_value(msg, str(field), "" if value is None else value, keys, prefix)
    elif isinstance(args, list):
        slots = msg.__slots__
        if len(args) > len(slots):
            raise MessageException(f"Too many arguments:\n * Given: {args}\n * Expected: {list(slots)}")
        if len(args) < len(slots):
            raise MessageException(f"Not enough arguments:\n * Given: {args}\n * Expected: {list(slots)}")
        for field, value in zip(slots, args):
            _fill_value(msg, field, value, keys, prefix)
    else:
        raise MessageException(f"invalid msg_args type: {args}")


def fill_message_args(msg: Any, args: List[Any] | None, keys: Dict[str, Any] | None = None) -> None:
    """Fill ``msg`` from YAML-parsed command-line ``args`` (genpy.fill_message_args)."""
    keys = keys or {}
    if args is None:
        args = []
    if len(args) == 1 and isinstance(args[0], dict):
        _fill(msg, args[0], keys)
    else:
        _fill(msg, list(args), keys)


def substitution_keys(now: Time | None = None) -> Dict[str, Any]:
    """``now`` -> current time, ``auto`` -> a std_msgs/Header stamped now."""
    if now is None:
        import time as _time

        now = Time.from_sec(_time.time())
    header_class = get_message_class("std_msgs/Header")
    return {"now": now, "auto": header_class(stamp=now)}


def printable_message_args(msg: Any, prefix: str = "") -> str:
    """``'a b'`` / ``'header.seq header.stamp ... data'`` (genpy.get_printable_message_args)."""
    parts: List[str] = []

    def walk(m: Any, pre: str) -> None:
        for field in m.__slots__:
            value = getattr(m, field)
            if isinstance(value, Message):
                walk(value, pre + field + ".")
            else:
                parts.append(pre + field)

    walk(msg if not isinstance(msg, type) else msg(), prefix)
    return " ".join(parts)
