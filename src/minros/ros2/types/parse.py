"""Parsing ROS 2 ``.msg``/``.srv``/``.action`` text, with rosidl's rules, into :mod:`.model`.

The rules are rosidl_adapter's (the ``.msg`` -> IDL step every ROS 2 build runs), so a
definition means here what it means to rclpy, its type hash included:

* Tabs count as spaces; ``#`` starts a comment anywhere on a line (also inside a quoted default
  or string constant, as in rosidl); blank lines are ignored.
* A line is ``TYPE NAME``, ``TYPE NAME DEFAULT`` or ``TYPE NAME=VALUE`` (a constant: a ``=``
  anywhere after the type). ``TYPE`` is a primitive, ``string<=N``/``wstring<=N``, ``pkg/Name``
  or ``Name`` (the same package: ROS 2 has no implicit ``Header``); then ``[N]`` (fixed),
  ``[<=N]`` (bounded) or ``[]``. ``time``/``duration`` (ROS 1's) mean builtin_interfaces'.
* Defaults and constants: ``true``/``false``/``1``/``0`` for bool, integers in range (decimal,
  or ``0x``/``0o``/``0b``), floats, strings with optional quotes (``\\'``/``\\"`` escape them),
  ``[a, b]`` for arrays with their length checked.
* A ``.srv`` has exactly one line ``---``; a ``.action`` exactly two.
* A struct without fields gets rosidl's placeholder ``uint8 structure_needs_at_least_one_member``.
* Services get their ``_Event`` struct (Iron and later), actions their derived services and
  messages, as rosidl_parser defines them.

Unlike rosidl, names are checked only for being identifiers (``[A-Za-z][A-Za-z0-9_]*``), not for
ROS 2's case conventions, so definitions converted from ROS 1 (``tf/tfMessage``) parse too.
Errors are :class:`minros.msgs.spec.MsgSpecError` naming the file and line.
"""

from __future__ import annotations

import codecs
import re
from typing import Any, Dict, List, Optional, Tuple

from minros.msgs.spec import MsgSpecError

from .model import (
    ARRAY,
    BOUNDED,
    EMPTY_MEMBER,
    INT_RANGES,
    PRIMITIVES,
    SCALAR,
    SEQUENCE,
    STRING_TYPES,
    TIME_ALIASES,
    ActionType,
    Constant,
    Field,
    FieldType,
    MessageType,
    ServiceType,
    Value,
    split_type_name,
)

_NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_PACKAGE_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")

SERVICE_EVENT_INFO = "service_msgs/msg/ServiceEventInfo"
UUID = "unique_identifier_msgs/msg/UUID"
TIME = "builtin_interfaces/msg/Time"


def parse_type(text: str, package: str) -> FieldType:
    """A ``.msg`` type spelling as a :class:`FieldType`; ``package`` qualifies bare names."""
    kind, size = SCALAR, 0
    base = text
    if text.endswith("]"):
        if "[" not in text:
            raise ValueError(f"type {text!r} ends with ']' but has no '['")
        index = text.rindex("[")
        base, inner = text[:index], text[index + 1:-1]
        if inner == "":
            kind = SEQUENCE
        else:
            kind = BOUNDED if inner.startswith("<=") else ARRAY
            digits = inner[2:] if kind == BOUNDED else inner
            if not digits.isdigit() or int(digits) <= 0:
                raise ValueError(f"the size of array type {text!r} must be an integer > 0, "
                                 f"optionally after '<=' for an upper bound")
            size = int(digits)
    string_bound = 0
    if base in PRIMITIVES:
        pass
    elif base.startswith(("string<=", "wstring<=")):
        base, _, bound = base.partition("<=")
        if not bound.isdigit() or int(bound) <= 0:
            raise ValueError(f"the upper bound of string type {text!r} must be an integer > 0")
        string_bound = int(bound)
    elif base in TIME_ALIASES:
        base = TIME_ALIASES[base]
    else:
        parts = base.split("/")
        if len(parts) == 1 and package:
            parts = [package, parts[0]]
        elif len(parts) == 3 and parts[1] == "msg":
            parts = [parts[0], parts[2]]
        if len(parts) != 2:
            raise ValueError(f"{text!r} is not a type: expected a primitive, 'pkg/Name' or "
                             f"'Name' (a type of the same package)")
        if not _PACKAGE_RE.match(parts[0]):
            raise ValueError(f"{parts[0]!r} (in type {text!r}) is not a valid package name")
        if not _NAME_RE.match(parts[1]):
            raise ValueError(f"{parts[1]!r} (in type {text!r}) is not a valid message name")
        base = f"{parts[0]}/msg/{parts[1]}"
    return FieldType(base, kind, size, string_bound)


# -- values ------------------------------------------------------------------------------------

def _parse_int(text: str, type_: str) -> int:
    lower, upper = INT_RANGES[type_]
    try:
        value = int(text)
    except ValueError:
        try:
            value = int(text, 0)
        except ValueError:
            raise ValueError(f"value {text!r} is not an integer ({type_} takes {lower}..{upper})") \
                from None
    if not lower <= value <= upper:
        raise ValueError(f"value {text!r} is out of range for {type_} ({lower}..{upper})")
    return value


def _parse_string(text: str, bound: int) -> str:
    for quote in ('"', "'"):
        if len(text) >= 2 and text.startswith(quote) and text.endswith(quote):
            text = text[1:-1]
            if re.search(r"(?<!\\)" + quote, text):
                raise ValueError(f"string {text!r}: inner quotes must be escaped with '\\'")
            text = text.replace("\\" + quote, quote)
            break
    if bound and len(text) > bound:
        raise ValueError(f"string {text!r} is longer than its bound of {bound} characters")
    return text


def parse_primitive(type_: FieldType, text: str) -> Value:
    """A scalar default or constant value of primitive type ``type_``."""
    base = type_.base
    if base == "bool":
        lowered = text.lower()
        if lowered not in ("true", "1", "false", "0"):
            raise ValueError(f"value {text!r} is not a bool: use true/false or 1/0")
        return lowered in ("true", "1")
    if base in INT_RANGES:
        return _parse_int(text, base)
    if base in ("float32", "float64"):
        try:
            return float(text)
        except ValueError:
            raise ValueError(f"value {text!r} is not a floating point number") from None
    if base in STRING_TYPES:
        return _parse_string(text, type_.string_bound)
    raise ValueError(f"type {type_} cannot have a default value (only primitive types can)")


def _split_string_array(text: str) -> List[str]:
    """The elements of a string array's ``[...]`` body: quoted ones may contain commas."""
    out: List[str] = []
    rest = text
    while rest.strip():
        rest = rest.lstrip(" ")
        if rest.startswith(","):
            raise ValueError(f"unexpected ',' at the start of {rest!r}")
        if rest[:1] in ('"', "'"):
            quote = rest[0]
            end = 1
            while True:
                end = rest.find(quote, end)
                if end == -1:
                    raise ValueError(f"string {rest!r} is not closed by {quote}")
                if rest[end - 1] != "\\":
                    break
                end += 1
            out.append(rest[1:end].replace("\\" + quote, quote))
            rest = rest[end + 1:]
        else:
            comma = rest.find(",")
            out.append(rest if comma == -1 else rest[:comma])
            rest = "" if comma == -1 else rest[comma:]
        rest = rest.lstrip(" ")
        if rest.startswith(","):
            rest = rest[1:]
    return out


def parse_value(type_: FieldType, text: str) -> Value:
    """A default value of ``type_`` (a primitive, or an array of them)."""
    if type_.is_nested:
        raise ValueError(f"type {type_} cannot have a default value (only primitive types can)")
    if not type_.is_array:
        return parse_primitive(type_, text)
    if not (text.startswith("[") and text.endswith("]")):
        raise ValueError(f"array value {text!r} must start with '[' and end with ']'")
    body = text[1:-1]
    if type_.is_string:
        items = [s.strip() for s in _split_string_array(body)]
    else:
        items = [s.strip() for s in body.split(",")] if body.strip() else []
    if type_.kind == ARRAY and len(items) != type_.size:
        raise ValueError(f"array value {text!r} must have exactly {type_.size} elements, "
                         f"not {len(items)}")
    if type_.kind == BOUNDED and len(items) > type_.size:
        raise ValueError(f"array value {text!r} must have at most {type_.size} elements, "
                         f"not {len(items)}")
    element = type_.element()
    values: Any = [parse_primitive(element, item) for item in items]
    return values  # type: ignore[no-any-return]


# rosidl writes a default into the type description as str() of the value its IDL parser
# reads back from the literal rosidl_adapter wrote; for strings and arrays the text takes two
# trips through escape processing, reproduced here so the descriptions match
_IDL_ESCAPES = re.compile(r"(\\[ntvbrfa\\?'\"]|\\[0-7]{1,3}|\\x[0-9a-fA-F]{1,2})")


def _idl_string(literal_body: str) -> str:
    value = _IDL_ESCAPES.sub(lambda m: codecs.decode(m.group(0), "unicode-escape"), literal_body)
    out, i = [], 0
    while i < len(value):
        if value[i] == "\\" and i + 1 < len(value) and value[i + 1] in ('"', "\\"):
            i += 1
        out.append(value[i])
        i += 1
    return "".join(out)


def default_text(type_: FieldType, value: Value) -> str:
    """The ``default_value`` rosidl writes for ``value`` in a type description."""
    if value is None:
        return ""
    if isinstance(value, list):
        body = repr(tuple(value)).replace("\\", "\\\\").replace('"', '\\"')
        return _idl_string(body)
    if isinstance(value, str):
        # rosidl_adapter decodes escapes of the UTF-8 bytes as latin-1 and writes the IDL file
        # as latin-1, which its IDL parser reads back as UTF-8: the round trip keeps non-ASCII
        try:
            escaped = value.encode().decode("unicode_escape").encode("latin-1").decode()
        except UnicodeError:
            escaped = value
        return _idl_string(escaped.replace('"', '\\"'))
    return str(value)


# -- messages ----------------------------------------------------------------------------------

def _error(reason: str, origin: str, lineno: Optional[int]) -> MsgSpecError:
    return MsgSpecError(reason, origin, lineno)


def parse_msg(text: str, name: str, origin: Optional[str] = None,
              first_line: int = 1) -> MessageType:
    """Parse ``.msg`` text for type ``name`` (``pkg/msg/Name`` or ``pkg/Name``).

    Raises :class:`MsgSpecError` naming ``origin`` (or the type) and the line on bad input.
    """
    try:
        package, namespace, short = split_type_name(name)
    except ValueError as exc:
        raise _error(str(exc), origin or name, None) from None
    full_name = f"{package}/{namespace}/{short}"
    where = origin or full_name
    fields: List[Field] = []
    constants: List[Constant] = []
    lines: Dict[str, int] = {}
    constant_lines: Dict[str, int] = {}
    for offset, raw in enumerate(text.replace("\t", " ").splitlines()):
        lineno = first_line + offset
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        type_text, _, rest = line.partition(" ")
        rest = rest.lstrip()
        if not rest:
            raise _error(f"invalid declaration {line!r}: expected 'TYPE NAME', "
                         f"'TYPE NAME DEFAULT' or 'TYPE NAME=VALUE'", where, lineno)
        try:
            if "=" in rest:
                cname, _, value_text = rest.partition("=")
                cname, value_text = cname.rstrip(), value_text.lstrip()
                if type_text not in PRIMITIVES:
                    raise ValueError(f"constant {cname!r} has type {type_text!r}: only "
                                     f"primitive types (not arrays) can be constants")
                if not _NAME_RE.match(cname):
                    raise ValueError(f"{cname!r} is not a valid constant name")
                if cname in constant_lines:
                    raise ValueError(f"duplicate constant {cname!r} (first declared on line "
                                     f"{constant_lines[cname]})")
                value = parse_primitive(FieldType(type_text), value_text)
                constants.append(Constant(cname, type_text, value))  # type: ignore[arg-type]
                constant_lines[cname] = lineno
                continue
            fname, _, default = rest.partition(" ")
            default = default.lstrip()
            ftype = parse_type(type_text, package)
            if not _NAME_RE.match(fname):
                raise ValueError(f"{fname!r} is not a valid field name")
            if fname in lines:
                raise ValueError(f"duplicate field name {fname!r} (first declared on line "
                                 f"{lines[fname]})")
            value = parse_value(ftype, default) if default else None
        except ValueError as exc:
            raise _error(str(exc), where, lineno) from None
        fields.append(Field(fname, ftype, value, default_text(ftype, value)))
        lines[fname] = lineno
    if not fields:
        fields.append(Field(EMPTY_MEMBER, FieldType("uint8")))
    return MessageType(full_name, fields, constants, text, where, lines)


def _split_lines(text: str, parts: int, kind: str, where: str) -> List[Tuple[str, int]]:
    """Split at lines that are exactly ``---``: [(part text, its first line number)]."""
    lines = text.splitlines()
    separators = [i for i, line in enumerate(lines) if line == "---"]
    if len(separators) != parts - 1:
        raise _error(f"a {kind} needs exactly {parts - 1} line(s) '---' separating its "
                     f"{'request and response' if parts == 2 else 'goal, result and feedback'}, "
                     f"found {len(separators)}", where, None)
    bounds = [-1] + separators + [len(lines)]
    return [("\n".join(lines[bounds[i] + 1:bounds[i + 1]]), bounds[i] + 2)
            for i in range(parts)]


def service_event(name: str, request: MessageType, response: MessageType) -> MessageType:
    """rosidl's ``Name_Event``: the service event info and at most one request/response."""
    return MessageType(f"{name}_Event", [
        Field("info", FieldType(SERVICE_EVENT_INFO)),
        Field("request", FieldType(request.name, BOUNDED, 1)),
        Field("response", FieldType(response.name, BOUNDED, 1)),
    ])


def make_service(name: str, request: MessageType, response: MessageType, with_event: bool = True,
                 text: str = "", origin: str = "") -> ServiceType:
    event = service_event(name, request, response) if with_event else None
    return ServiceType(name, request, response, event, text, origin)


def parse_srv(text: str, name: str, origin: Optional[str] = None,
              with_event: bool = True) -> ServiceType:
    """Parse ``.srv`` text for service ``name`` (``pkg/srv/Name`` or ``pkg/Name``)."""
    package, _ns, short = split_type_name(name)
    full = f"{package}/srv/{short}"
    where = origin or full
    (req_text, req_line), (resp_text, resp_line) = _split_lines(text, 2, "service", where)
    request = parse_msg(req_text, f"{full}_Request", where, req_line)
    response = parse_msg(resp_text, f"{full}_Response", where, resp_line)
    return make_service(full, request, response, with_event, text, where)


def make_action(name: str, goal: MessageType, result: MessageType, feedback: MessageType,
                with_event: bool = True, text: str = "", origin: str = "") -> ActionType:
    """An action with the services and message rosidl derives from its three parts."""
    send_goal = make_service(
        f"{name}_SendGoal",
        MessageType(f"{name}_SendGoal_Request",
                    [Field("goal_id", FieldType(UUID)), Field("goal", FieldType(goal.name))]),
        MessageType(f"{name}_SendGoal_Response",
                    [Field("accepted", FieldType("bool")), Field("stamp", FieldType(TIME))]),
        with_event)
    get_result = make_service(
        f"{name}_GetResult",
        MessageType(f"{name}_GetResult_Request", [Field("goal_id", FieldType(UUID))]),
        MessageType(f"{name}_GetResult_Response",
                    [Field("status", FieldType("int8")), Field("result", FieldType(result.name))]),
        with_event)
    feedback_message = MessageType(f"{name}_FeedbackMessage", [
        Field("goal_id", FieldType(UUID)), Field("feedback", FieldType(feedback.name))])
    return ActionType(name, goal, result, feedback, send_goal, get_result, feedback_message,
                      text, origin)


def parse_action(text: str, name: str, origin: Optional[str] = None,
                 with_event: bool = True) -> ActionType:
    """Parse ``.action`` text for action ``name`` (``pkg/action/Name`` or ``pkg/Name``)."""
    package, _ns, short = split_type_name(name)
    full = f"{package}/action/{short}"
    where = origin or full
    parts = _split_lines(text, 3, "action", where)
    goal, result, feedback = (parse_msg(part, f"{full}_{suffix}", where, line)
                              for (part, line), suffix in zip(parts,
                                                              ("Goal", "Result", "Feedback")))
    return make_action(full, goal, result, feedback, with_event, text, where)
