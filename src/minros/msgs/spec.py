"""Parsing ``.msg``/``.srv`` text into specs, and the two texts genmsg derives from them.

The rules follow genmsg (msg_loader.py, gentools.py) so md5 sums and ``message_definition``
texts match real ROS byte for byte:

* ``#`` starts a comment; blank lines are ignored.
* A line containing ``=`` (after comment stripping) is a constant ``TYPE NAME=VALUE``; for
  ``string`` constants the value is everything after the first ``=`` of the *raw* line
  (comments are part of the value), stripped.
* ``Header`` means ``std_msgs/Header``; an unqualified non-builtin type belongs to the
  current package; ``T[]`` is a variable-length array, ``T[N]`` a fixed one.
* A ``.srv`` splits at the first line that *starts with* ``---``.
* md5 text: constants first (``type name=raw value``), then fields, embedded message types
  replaced by their md5 (array brackets dropped); the result is stripped.
* full text: the raw file text, then each embedded type once (depth-first, field order)
  after a line of 80 ``=`` and ``MSG: pkg/Type``; the final newline is dropped.
"""

from __future__ import annotations

import ast
import hashlib
import re
from typing import Callable, Dict, List, Tuple

PRIMITIVE_TYPES = (
    "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
    "float32", "float64", "string", "bool", "char", "byte",
)
BUILTIN_TYPES = PRIMITIVE_TYPES + ("time", "duration")
HEADER = "Header"
HEADER_FULL_NAME = "std_msgs/Header"
SEPARATOR = "=" * 80

_BASE_NAME_RE = re.compile(r"^[A-Za-z][\w]*$")
_RESOURCE_NAME_RE = re.compile(r"^[A-Za-z][\w/]*$")
_INT_BOUNDS = {
    "int8": (-(2 ** 7), 2 ** 7 - 1), "uint8": (0, 2 ** 8 - 1),
    "int16": (-(2 ** 15), 2 ** 15 - 1), "uint16": (0, 2 ** 16 - 1),
    "int32": (-(2 ** 31), 2 ** 31 - 1), "uint32": (0, 2 ** 32 - 1),
    "int64": (-(2 ** 63), 2 ** 63 - 1), "uint64": (0, 2 ** 64 - 1),
    # genmsg's bounds check: byte is signed, char unsigned
    "byte": (-(2 ** 7), 2 ** 7 - 1), "char": (0, 2 ** 8 - 1),
}


class MsgSpecError(ValueError):
    """A ``.msg``/``.srv`` definition is malformed; the text names the file and line."""

    def __init__(self, message: str, filename: str | None = None,
                 lineno: int | None = None) -> None:
        self.filename = filename
        self.lineno = lineno
        self.reason = message
        where = filename or "<string>"
        if lineno is not None:
            where = f"{where}:{lineno}"
        super().__init__(f"{where}: {message}")


class ConstantRangeError(ValueError):
    """A constant's value does not fit its integer type (genmsg reports it apart from a value
    that is not a number at all)."""


def is_legal_base_name(name: str) -> bool:
    return bool(_BASE_NAME_RE.match(name))


def is_legal_resource_name(name: str) -> bool:
    return bool(_RESOURCE_NAME_RE.match(name)) and "//" not in name


def is_builtin(base_type: str) -> bool:
    """Whether ``base_type`` (no array suffix) is a primitive, time or duration."""
    return base_type in BUILTIN_TYPES


def split_array(type_: str) -> Tuple[str, bool, int | None]:
    """``'float64[9]'`` -> ``('float64', True, 9)``; ``'string[]'`` -> ``('string', True, None)``."""
    if "[" not in type_:
        return type_, False, None
    base, _, rest = type_.partition("[")
    if not rest.endswith("]") or "[" in rest:
        raise ValueError(f"only one-dimensional arrays are supported: {type_}")
    inner = rest[:-1]
    if inner == "":
        return base, True, None
    if not inner.isdigit():
        raise ValueError(f"invalid array length [{inner}] in {type_}")
    return base, True, int(inner)


class Field:
    """One field of a message: its name and resolved type."""

    __slots__ = ("name", "type", "base_type", "is_array", "array_len", "is_builtin", "is_header")

    def __init__(self, name: str, type_: str) -> None:
        self.name = name
        self.type = type_
        self.base_type, self.is_array, self.array_len = split_array(type_)
        self.is_builtin = is_builtin(self.base_type)
        self.is_header = type_ in (HEADER, HEADER_FULL_NAME, "roslib/Header")

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Field) and (self.name, self.type) == (other.name, other.type)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"[{self.name}, {self.type}, {self.base_type}, {self.is_array}, {self.array_len}]"


class Constant:
    """A constant declaration; ``val_text`` is the raw value text used by md5 sums."""

    __slots__ = ("type", "name", "value", "val_text")

    def __init__(self, type_: str, name: str, value: object, val_text: str) -> None:
        self.type = type_
        self.name = name
        self.value = value
        self.val_text = val_text

    @property
    def val(self) -> object:
        """genmsg's name for :attr:`value`."""
        return self.value

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Constant) and \
            (self.type, self.name, self.value) == (other.type, other.name, other.value)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"{self.type} {self.name}={self.value}"

    __str__ = __repr__


class MsgSpec:
    """A parsed message: fields, constants and the raw text it came from."""

    def __init__(self, full_name: str, fields: List[Field], constants: List[Constant],
                 text: str, filename: str | None = None,
                 field_lines: Dict[str, int] | None = None) -> None:
        self.full_name = full_name
        self.package, _, self.short_name = full_name.rpartition("/")
        self.fields = fields
        self.constants = constants
        self.text = text
        self.filename = filename
        #: field name -> line of ``filename`` declaring it (errors about a field cite it)
        self.field_lines = field_lines or {}

    @property
    def names(self) -> List[str]:
        return [f.name for f in self.fields]

    @property
    def types(self) -> List[str]:
        return [f.type for f in self.fields]

    @property
    def has_header(self) -> bool:
        return bool(self.fields) and self.fields[0].type == HEADER_FULL_NAME \
            and self.fields[0].name == "header"

    def dependencies(self) -> List[str]:
        """Embedded message types, once each, in field order (first-order only)."""
        out: List[str] = []
        for f in self.fields:
            if not f.is_builtin and f.base_type not in out:
                out.append(f.base_type)
        return out

    def __repr__(self) -> str:
        return f"MsgSpec({self.full_name})"


class SrvSpec:
    """A parsed service: request and response message specs."""

    def __init__(self, full_name: str, request: MsgSpec, response: MsgSpec, text: str,
                 filename: str | None = None) -> None:
        self.full_name = full_name
        self.package, _, self.short_name = full_name.rpartition("/")
        self.request = request
        self.response = response
        self.text = text
        self.filename = filename

    def __repr__(self) -> str:
        return f"SrvSpec({self.full_name})"


def _strip_comment(line: str) -> str:
    return line.split("#", 1)[0].strip()


def _convert_constant(type_: str, text: str) -> object:
    if type_ in ("float32", "float64"):
        return float(text)
    if type_ == "string":
        return text.strip()
    if type_ == "bool":
        return bool(ast.literal_eval(text))
    if type_ in _INT_BOUNDS:
        value = int(text)
        lower, upper = _INT_BOUNDS[type_]
        if not lower <= value <= upper:
            raise ConstantRangeError(f"cannot coerce [{value}] to {type_} (out of bounds)")
        return value
    raise ValueError(f"invalid constant type: [{type_}]")


def _parse_constant(orig_line: str, clean: str) -> Constant:
    words = clean.split()
    type_ = words[0]
    if type_ not in PRIMITIVE_TYPES:
        raise ValueError(f"{type_} is not a legal constant type (only primitive types can be constants)")
    if type_ == "string":
        # everything right of the first '=' of the raw line, comments included
        idx = orig_line.find("=")
        name = orig_line[orig_line.find(" ") + 1:idx].strip()
        raw = orig_line[idx + 1:]
    else:
        parts = [p.strip() for p in " ".join(words[1:]).split("=")]
        if len(parts) != 2:
            raise ValueError(f"invalid constant declaration: {orig_line.strip()}")
        name, raw = parts
    if not is_legal_base_name(name):
        raise ValueError(f"{name!r} is not a legal constant name")
    try:
        value = _convert_constant(type_, raw)
    except (ValueError, SyntaxError) as exc:
        raise ValueError(f"invalid constant value {raw.strip()!r} for {type_}: {exc}") from None
    return Constant(type_, name, value, raw.strip())


def _resolve_field_type(type_: str, package: str) -> str:
    base, is_array, array_len = split_array(type_)
    suffix = type_[len(base):]
    if base == HEADER:
        base = HEADER_FULL_NAME
    elif not is_builtin(base) and "/" not in base and package:
        base = f"{package}/{base}"
    return base + suffix


def _parse_field(clean: str, package: str) -> Tuple[str, str]:
    words = clean.split()
    if len(words) != 2:
        raise ValueError(f"invalid declaration {clean!r}: expected 'TYPE NAME' or 'TYPE NAME=VALUE'")
    type_, name = words
    if not is_legal_base_name(name):
        raise ValueError(f"{name!r} is not a legal message field name")
    try:
        base, _is_array, _n = split_array(type_)
    except ValueError as exc:
        raise ValueError(f"{type_!r} is not a legal message field type: {exc}") from None
    if not is_legal_resource_name(base) or base.count("/") > 1 or base.endswith("/"):
        raise ValueError(f"{type_!r} is not a legal message field type")
    return _resolve_field_type(type_, package), name


def parse_msg(text: str, full_name: str, filename: str | None = None,
              first_line: int = 1) -> MsgSpec:
    """Parse ``.msg`` text for type ``full_name`` ('pkg/Name').

    Raises :class:`MsgSpecError` naming ``filename`` and the line on bad input.
    """
    package = full_name.rpartition("/")[0]
    fields: List[Field] = []
    constants: List[Constant] = []
    seen: Dict[str, int] = {}
    for offset, orig_line in enumerate(text.split("\n")):
        lineno = first_line + offset
        clean = _strip_comment(orig_line)
        if not clean:
            continue
        try:
            if "=" in clean:
                const = _parse_constant(orig_line, clean)
                constants.append(const)
                continue
            type_, name = _parse_field(clean, package)
        except ValueError as exc:
            raise MsgSpecError(str(exc), filename or full_name, lineno) from None
        if name in seen:
            raise MsgSpecError(f"duplicate field name {name!r} (first declared on line {seen[name]})",
                               filename or full_name, lineno)
        seen[name] = lineno
        fields.append(Field(name, type_))
    return MsgSpec(full_name, fields, constants, text, filename, seen)


def split_srv_text(text: str) -> Tuple[str, str, int]:
    """Split ``.srv`` text as genmsg does: (request text, response text, response first line)."""
    request: List[str] = []
    response: List[str] = []
    accum = request
    response_line = 0
    for lineno, line in enumerate(text.split("\n"), start=1):
        if line.startswith("---"):
            if accum is request:
                response_line = lineno + 1
            accum = response
        else:
            accum.append(line + "\n")
    return "".join(request), "".join(response), response_line


def parse_srv(text: str, full_name: str, filename: str | None = None) -> SrvSpec:
    """Parse ``.srv`` text for service type ``full_name``."""
    req_text, resp_text, resp_line = split_srv_text(text)
    request = parse_msg(req_text, full_name + "Request", filename or full_name, 1)
    response = parse_msg(resp_text, full_name + "Response", filename or full_name, resp_line or 1)
    return SrvSpec(full_name, request, response, text, filename)


# ---------------------------------------------------------------------------------------------
# md5 sums and full text

def compute_md5_text(spec: MsgSpec, md5_of: Callable[[str], str]) -> str:
    """genmsg's md5 text for ``spec``; ``md5_of(type)`` gives an embedded type's md5."""
    lines = [f"{c.type} {c.name}={c.val_text}" for c in spec.constants]
    for f in spec.fields:
        if f.is_builtin:
            lines.append(f"{f.type} {f.name}")
        else:
            lines.append(f"{md5_of(f.base_type)} {f.name}")
    return "\n".join(lines).strip()


def md5_hex(text: str) -> str:
    return hashlib.md5(text.encode()).hexdigest()


def all_dependencies(spec: MsgSpec, get_spec: Callable[[str], MsgSpec]) -> List[str]:
    """Embedded types, depth first in field order, each once (genmsg's _unique_deps order)."""
    out: List[str] = []

    def visit(s: MsgSpec, stack: Tuple[str, ...]) -> None:
        for f in s.fields:
            if f.is_builtin:
                continue
            dep = f.base_type
            if dep in stack:
                raise MsgSpecError(f"recursive message definition: {' -> '.join(stack + (dep,))}",
                                   s.filename or s.full_name)
            if dep not in out:
                out.append(dep)
            visit(get_spec(dep), stack + (dep,))

    visit(spec, (spec.full_name,))
    return out


def compute_full_text(spec: MsgSpec, get_spec: Callable[[str], MsgSpec]) -> str:
    """The ``message_definition`` text (genmsg compute_full_text)."""
    parts = [spec.text, "\n"]
    for dep in all_dependencies(spec, get_spec):
        parts.append(SEPARATOR + "\n")
        parts.append(f"MSG: {dep}\n")
        parts.append(get_spec(dep).text)
        parts.append("\n")
    return "".join(parts)[:-1]


def split_full_text(full_text: str) -> List[Tuple[str | None, str]]:
    """Split a ``message_definition`` into ``[(None, core text), (dep type, dep text), ...]``.

    As genpy.dynamic: blocks are separated by ``"\n" + "=" * 80 + "\n"``; each dependency block
    starts with a ``MSG: pkg/Type`` line. Raises :class:`MsgSpecError` if a block lacks it.
    """
    full_text = full_text.replace("roslib/Header", HEADER_FULL_NAME)
    splits = full_text.split("\n" + SEPARATOR + "\n")
    blocks: List[Tuple[str | None, str]] = [(None, splits[0])]
    for number, block in enumerate(splits[1:], start=1):
        first, _, rest = block.partition("\n")
        if not first.startswith("MSG: "):
            raise MsgSpecError(f"block {number} of the definition lacks its 'MSG: pkg/Type' line",
                               "<message_definition>")
        blocks.append((first[5:].strip(), rest))
    return blocks


# ---------------------------------------------------------------------------------------------
# .action files (actionlib_msgs' genaction)

ACTION_AUTOGEN = "# ====== DO NOT MODIFY! AUTOGENERATED FROM AN ACTION DEFINITION ======"
#: suffixes of the message types generated from ``Name.action``, longest first
ACTION_SUFFIXES = ("ActionFeedback", "ActionResult", "ActionGoal", "Action", "Feedback",
                   "Result", "Goal")


def action_message_texts(action_text: str, short_name: str) -> Dict[str, str]:
    """The seven ``.msg`` texts catkin generates from ``short_name.action``, as genaction.

    The action text splits into goal, result and feedback at lines starting with ``---``;
    each part keeps its lines (each followed by a newline) after the autogenerated banner.
    """
    pieces: List[List[str]] = [[]]
    for line in action_text.split("\n"):
        if line.startswith("---"):
            pieces.append([])
        else:
            pieces[-1].append(line + "\n")
    if len(pieces) != 3:
        raise MsgSpecError(f"an action needs goal, result and feedback separated by two '---' "
                           f"lines, found {len(pieces) - 1}", f"{short_name}.action")
    goal, result, feedback = ("".join(p) for p in pieces)
    banner = ACTION_AUTOGEN + "\n"
    n = short_name
    return {
        f"{n}Goal": banner + goal,
        f"{n}Result": banner + result,
        f"{n}Feedback": banner + feedback,
        f"{n}Action": banner + f"\n{n}ActionGoal action_goal\n{n}ActionResult action_result\n"
                               f"{n}ActionFeedback action_feedback\n",
        f"{n}ActionGoal": banner + f"\nHeader header\nactionlib_msgs/GoalID goal_id\n{n}Goal goal\n",
        f"{n}ActionResult": banner + f"\nHeader header\nactionlib_msgs/GoalStatus status\n{n}Result result\n",
        f"{n}ActionFeedback": banner + f"\nHeader header\nactionlib_msgs/GoalStatus status\n"
                                       f"{n}Feedback feedback\n",
    }
