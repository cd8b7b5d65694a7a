"""ROS messages <-> rosbridge JSON values, with the rules of rosbridge 0.11 (ROS 1).

``message_to_json(msg)`` gives the ``msg`` object of a ``publish`` op and the ``values`` of a
``service_response``; ``populate_message(values, msg, now)`` fills a message from a client's
``publish``/``call_service``. The rules, as rosbridge_library's message_conversion applies them:

* ``uint8[]``/``char[]`` (any length) travel as a base64 string; a JSON list of ints is accepted
  on input too;
* ``time``/``duration`` are ``{"secs": s, "nsecs": n}``; a time may be given as ``"now"``;
* float NaN and +-Inf become ``null`` (JSON has neither);
* a ``Header`` is stamped with the current time before the client's fields are applied, so a
  client may leave out the header or just its stamp (the protocol's rule; rosbridge 0.11's
  code stamps only a header the client sends, even ``{}``);
* type checks: a JSON int fills any numeric field, a float only float fields, a bool only bool
  fields, a string only string fields; an unknown field is an error.

Pure functions over genpy-style classes (``__slots__``, ``_slot_types``, ``_type``): no ROS, no
sockets. Errors are :class:`ConversionError` with rosbridge's wording.
"""

from __future__ import annotations

import base64
import binascii
import math
import re
from typing import Any, Callable, Dict, List, Tuple

#: types whose values are ``{"secs", "nsecs"}``
TIME_TYPES = ("time", "duration")
PRIMITIVES = frozenset(("bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32",
                        "uint32", "int64", "uint64", "float32", "float64", "string"))
FLOATS = frozenset(("float32", "float64"))
INTS = frozenset(("byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32",
                  "int64", "uint64"))
HEADER_TYPES = frozenset(("Header", "std_msgs/Header", "roslib/Header"))
_ARRAY = re.compile(r"^(.*)\[(\d*)\]$")


class ConversionError(ValueError):
    """A client's JSON does not fit the message type (rosbridge's texts)."""


def split_array(slot_type: str) -> Tuple[str, bool]:
    """``"uint8[16]"`` -> ``("uint8", True)``; ``"string"`` -> ``("string", False)``."""
    match = _ARRAY.match(slot_type)
    if match:
        return match.group(1), True
    return slot_type, False


def is_binary(slot_type: str) -> bool:
    """``uint8[]``, ``uint8[N]``, ``char[]``, ``char[N]``: sent as base64 / CBOR bytes."""
    base, array = split_array(slot_type)
    return array and base in ("uint8", "char")


# -- ROS -> JSON ---------------------------------------------------------------------------

def _float_value(value: float) -> Any:
    return None if (math.isnan(value) or math.isinf(value)) else value


def _field_converter(slot_type: str) -> Callable[[Any], Any]:
    base, array = split_array(slot_type)
    if array:
        if base in ("uint8", "char"):
            return lambda v: base64.b64encode(bytes(v)).decode("ascii")
        if base in FLOATS:
            return lambda v: [_float_value(x) for x in v]
        if base in PRIMITIVES:
            return list
        if base in TIME_TYPES:
            return lambda v: [{"secs": t.secs, "nsecs": t.nsecs} for t in v]
        return lambda v: [message_to_json(x) for x in v]
    if base in FLOATS:
        return _float_value
    if base in PRIMITIVES:
        return _same
    if base in TIME_TYPES:
        return lambda t: {"secs": t.secs, "nsecs": t.nsecs}
    return message_to_json


def _same(value: Any) -> Any:
    return value


_PLANS: Dict[type, List[Tuple[str, Callable[[Any], Any]]]] = {}


def _plan(cls: type) -> List[Tuple[str, Callable[[Any], Any]]]:
    plan = _PLANS.get(cls)
    if plan is None:
        plan = [(name, _field_converter(slot_type))
                for name, slot_type in zip(cls.__slots__, cls._slot_types)]
        _PLANS[cls] = plan
    return plan


def message_to_json(msg: Any) -> Dict[str, Any]:
    """The rosbridge JSON object of a message (fields in definition order)."""
    return {name: convert(getattr(msg, name)) for name, convert in _plan(type(msg))}


# -- JSON -> ROS ---------------------------------------------------------------------------

def _type_name(value: Any) -> str:
    return f"<class '{type(value).__name__}'>"


def _mismatch(root: str, stack: List[str], expected: str, value: Any) -> ConversionError:
    if not stack:
        return ConversionError(f"Expected a JSON object for type {root} but received a "
                               f"{_type_name(value)}")
    return ConversionError(f"{root} message requires a {expected} for field "
                           f"{'.'.join(stack)}, but got a {_type_name(value)}")


def _to_primitive(value: Any, slot_type: str, root: str, stack: List[str]) -> Any:
    kind = type(value)
    if kind is bool:
        ok = slot_type == "bool"
    elif kind is int:
        ok = slot_type in INTS or slot_type in FLOATS
    elif kind is float:
        ok = slot_type in FLOATS
    elif kind is str:
        ok = slot_type == "string"
    else:
        ok = False
    if not ok:
        raise _mismatch(root, stack, slot_type, value)
    return value


def _to_binary(value: Any, root: str, stack: List[str], slot_type: str) -> bytes:
    if isinstance(value, str):
        try:
            return base64.b64decode(value, validate=True)
        except (binascii.Error, ValueError):
            raise ConversionError(f"{root} message requires base64 text or a list of ints for "
                                  f"field {'.'.join(stack)} ({slot_type})") from None
    if isinstance(value, list):
        try:
            return bytes(value)
        except (TypeError, ValueError):
            raise ConversionError(f"{root} message requires ints 0..255 for field "
                                  f"{'.'.join(stack)} ({slot_type})") from None
    raise _mismatch(root, stack, slot_type, value)


def _to_time(value: Any, current: Any, slot_type: str, root: str, stack: List[str],
             now: Callable[[], Any]) -> Any:
    if slot_type == "time" and value == "now":
        return now()
    if not isinstance(value, dict):
        raise _mismatch(root, stack, slot_type, value)
    for key in ("secs", "nsecs"):
        if key in value:
            part = value[key]
            if type(part) is not int:
                raise _mismatch(root, stack + [key], "int32", part)
            setattr(current, key, part)
    return current


def _new_element(base: str) -> Any:
    from minros.msgs import get_message_class

    return get_message_class(base)()


def _to_value(value: Any, slot_type: str, current: Any, root: str, stack: List[str],
              now: Callable[[], Any]) -> Any:
    base, array = split_array(slot_type)
    if array:
        if base in ("uint8", "char"):
            return _to_binary(value, root, stack, slot_type)
        if not isinstance(value, list):
            raise _mismatch(root, stack, slot_type, value)
        if base in PRIMITIVES:
            return [_to_primitive(x, base, root, stack) for x in value]
        if base in TIME_TYPES:
            from minros.msgs import Duration, Time

            cls = Time if base == "time" else Duration
            return [_to_time(x, cls(), base, root, stack, now) for x in value]
        out = []
        for item in value:
            element = _new_element(base)
            out.append(_populate(item, element, root, stack, now))
        return out
    if base in PRIMITIVES:
        return _to_primitive(value, base, root, stack)
    if base in TIME_TYPES:
        return _to_time(value, current, base, root, stack, now)
    return _populate(value, current, root, stack, now)


def _populate(values: Any, msg: Any, root: str, stack: List[str],
              now: Callable[[], Any]) -> Any:
    if not isinstance(values, dict):
        raise _mismatch(root, stack, msg._type, values)
    if msg._type in HEADER_TYPES:
        stamp = now()
        msg.stamp.secs = stamp.secs
        msg.stamp.nsecs = stamp.nsecs
    slots = dict(zip(msg.__slots__, msg._slot_types))
    for name, slot_type in slots.items():  # a header the client left out is stamped now
        if slot_type in HEADER_TYPES and name not in values:
            _populate({}, getattr(msg, name), root, stack + [name], now)
    for name, value in values.items():
        field_stack = stack + [name]
        slot_type = slots.get(name)
        if slot_type is None:
            raise ConversionError(f"Message type {root} does not have a field "
                                  f"{'.'.join(field_stack)}")
        current = getattr(msg, name)
        setattr(msg, name, _to_value(value, slot_type, current, root, field_stack, now))
    return msg


def populate_message(values: Any, msg: Any, now: Callable[[], Any]) -> Any:
    """Fill ``msg`` (an instance) from rosbridge JSON ``values``; returns ``msg``.

    ``now()`` gives the current ROS time (a ``Time``) for headers and ``"now"``.
    Raises ConversionError naming the field and the expected type.
    """
    return _populate(values, msg, msg._type, [], now)


def request_values(args: Any, request: Any) -> Dict[str, Any]:
    """``call_service`` args as rosbridge reads them: a dict of fields, a list of the fields in
    order, anything else as no arguments."""
    if isinstance(args, list):
        return dict(zip(request.__slots__, args))
    if isinstance(args, dict):
        return args
    return {}
