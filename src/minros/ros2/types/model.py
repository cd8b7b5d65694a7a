"""ROS 2 interface types as data: messages, their fields and constants, services, actions.

Names are rosidl's: a message type is ``pkg/msg/Name``, a service ``pkg/srv/Name`` with the
structs ``pkg/srv/Name_Request``, ``_Response`` and ``_Event``; an action ``pkg/action/Name``
with ``_Goal``, ``_Result``, ``_Feedback``, the services ``_SendGoal`` and ``_GetResult`` and
the message ``_FeedbackMessage``. Every one of these is a :class:`MessageType` (a struct with
members), so type descriptions, hashes and CDR treat them alike.

A field's type keeps the ``.msg`` spelling (``byte``, ``char``, ``string<=10``, ``T[<=3]``), and
knows what rosidl makes of it: ``byte`` is IDL ``octet``, ``char`` is ``uint8``, ``time`` and
``duration`` (accepted for definitions converted from ROS 1) are ``builtin_interfaces``'.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple, Union

#: the primitive types of a ROS 2 ``.msg`` (rosidl_adapter's, without time/duration)
PRIMITIVES = (
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
    "int32", "uint32", "int64", "uint64", "string", "wstring",
)
STRING_TYPES = ("string", "wstring")
#: ROS 1 compatibility names rosidl reserves and minros resolves
TIME_ALIASES = {"time": "builtin_interfaces/msg/Time", "duration": "builtin_interfaces/msg/Duration"}

#: size in bytes of each fixed-size primitive (CDR alignment is the same)
PRIMITIVE_SIZE = {
    "bool": 1, "byte": 1, "char": 1, "int8": 1, "uint8": 1, "int16": 2, "uint16": 2,
    "int32": 4, "uint32": 4, "int64": 8, "uint64": 8, "float32": 4, "float64": 8,
}
#: struct codes (little endian) of the fixed-size primitives
STRUCT_CODE = {
    "bool": "?", "byte": "B", "char": "B", "int8": "b", "uint8": "B", "int16": "h",
    "uint16": "H", "int32": "i", "uint32": "I", "int64": "q", "uint64": "Q", "float32": "f",
    "float64": "d",
}
INT_RANGES = {
    "byte": (0, 255), "char": (0, 255), "int8": (-(2 ** 7), 2 ** 7 - 1), "uint8": (0, 255),
    "int16": (-(2 ** 15), 2 ** 15 - 1), "uint16": (0, 2 ** 16 - 1),
    "int32": (-(2 ** 31), 2 ** 31 - 1), "uint32": (0, 2 ** 32 - 1),
    "int64": (-(2 ** 63), 2 ** 63 - 1), "uint64": (0, 2 ** 64 - 1),
}
#: the member rosidl adds to a struct without fields (IDL has no empty structs)
EMPTY_MEMBER = "structure_needs_at_least_one_member"

#: array kinds
SCALAR, ARRAY, BOUNDED, SEQUENCE = "", "array", "bounded", "sequence"

Value = Union[None, bool, int, float, str, List[bool], List[int], List[float], List[str]]


@dataclass(frozen=True)
class FieldType:
    """The type of one member: ``base`` (a primitive or ``pkg/msg/Name``), its string bound,
    and whether it is a fixed array (``size`` elements), a bounded or an unbounded sequence."""

    base: str
    kind: str = SCALAR
    size: int = 0  # elements of a fixed array, or the bound of a bounded sequence
    string_bound: int = 0  # string<=N / wstring<=N; 0: unbounded

    @property
    def is_primitive(self) -> bool:
        return self.base in PRIMITIVES

    @property
    def is_string(self) -> bool:
        return self.base in STRING_TYPES

    @property
    def is_nested(self) -> bool:
        return self.base not in PRIMITIVES

    @property
    def is_array(self) -> bool:
        """Any of ``T[N]``, ``T[<=N]``, ``T[]``."""
        return self.kind != SCALAR

    @property
    def is_sequence(self) -> bool:
        """``T[]`` or ``T[<=N]``: a length prefix on the wire."""
        return self.kind in (BOUNDED, SEQUENCE)

    def element(self) -> FieldType:
        """The type of one element (the type itself for a scalar)."""
        return FieldType(self.base, SCALAR, 0, self.string_bound)

    def msg_text(self) -> str:
        """The ``.msg`` spelling: ``float64[9]``, ``string<=8[<=3]``, ``geometry_msgs/Point[]``."""
        base = self.base
        if self.is_nested:
            base = f"{base.split('/')[0]}/{base.rsplit('/', 1)[1]}"
        if self.string_bound:
            base += f"<={self.string_bound}"
        if self.kind == ARRAY:
            return f"{base}[{self.size}]"
        if self.kind == BOUNDED:
            return f"{base}[<={self.size}]"
        if self.kind == SEQUENCE:
            return f"{base}[]"
        return base

    def __str__(self) -> str:
        return self.msg_text()


@dataclass(frozen=True)
class Field:
    """A member of a struct; ``default`` is the parsed ``.msg`` default value, if any."""

    name: str
    type: FieldType
    default: Value = None
    #: the default as rosidl writes it in a type description (``str()`` of the IDL value)
    default_text: str = ""


@dataclass(frozen=True)
class Constant:
    name: str
    type: str
    value: Union[bool, int, float, str]


@dataclass
class MessageType:
    """A struct: a message, or a part of a service or action."""

    name: str  # pkg/msg/Name, pkg/srv/Name_Request, pkg/action/Name_Goal, ...
    fields: List[Field]
    constants: List[Constant] = field(default_factory=list)
    #: the definition text it was parsed from ('' for derived types), and where it came from
    text: str = ""
    origin: str = ""
    #: field name -> line of ``origin`` declaring it (errors about a field cite it)
    field_lines: Dict[str, int] = field(default_factory=dict)

    @property
    def package(self) -> str:
        return self.name.split("/", 1)[0]

    @property
    def short_name(self) -> str:
        return self.name.rsplit("/", 1)[1]

    @property
    def namespace(self) -> str:
        """``msg``, ``srv`` or ``action``."""
        return self.name.split("/")[1]

    def dependencies(self) -> List[str]:
        """Nested types, once each, in field order (first order only)."""
        out: List[str] = []
        for f in self.fields:
            if f.type.is_nested and f.type.base not in out:
                out.append(f.type.base)
        return out

    def field(self, name: str) -> Optional[Field]:
        for f in self.fields:
            if f.name == name:
                return f
        return None

    @property
    def is_empty(self) -> bool:
        """Whether rosidl had to add its placeholder member (the definition has no fields)."""
        return len(self.fields) == 1 and self.fields[0].name == EMPTY_MEMBER

    def __repr__(self) -> str:
        return f"MessageType({self.name})"


@dataclass
class ServiceType:
    name: str  # pkg/srv/Name
    request: MessageType
    response: MessageType
    event: Optional[MessageType]  # None before Iron (Humble)
    text: str = ""
    origin: str = ""

    def __repr__(self) -> str:
        return f"ServiceType({self.name})"


@dataclass
class ActionType:
    name: str  # pkg/action/Name
    goal: MessageType
    result: MessageType
    feedback: MessageType
    send_goal: ServiceType
    get_result: ServiceType
    feedback_message: MessageType
    text: str = ""
    origin: str = ""

    def __repr__(self) -> str:
        return f"ActionType({self.name})"


def split_type_name(name: str) -> Tuple[str, str, str]:
    """``pkg/msg/Name`` -> (pkg, msg, Name); ``pkg/Name`` is taken as a message."""
    parts = name.strip().split("/")
    if len(parts) == 2 and all(parts):
        return parts[0], "msg", parts[1]
    if len(parts) == 3 and all(parts):
        return parts[0], parts[1], parts[2]
    raise ValueError(f"invalid ROS 2 type name [{name}]: expected 'pkg/msg/Name' or 'pkg/Name'")


def dds_type_name(name: str) -> str:
    """The type name DDS endpoints carry: ``std_msgs/msg/String`` -> ``std_msgs::msg::dds_::String_``
    (services' parts: ``pkg::srv::dds_::Name_Request_``)."""
    pkg, ns, short = split_type_name(name)
    return f"{pkg}::{ns}::dds_::{short}_"


def from_dds_type_name(dds_name: str) -> str:
    """``std_msgs::msg::dds_::String_`` -> ``std_msgs/msg/String``."""
    parts = dds_name.split("::")
    if len(parts) != 4 or parts[2] != "dds_" or not parts[3].endswith("_") or len(parts[3]) < 2:
        raise ValueError(f"not a ROS 2 DDS type name: {dds_name!r} "
                         f"(expected 'pkg::msg::dds_::Name_')")
    return f"{parts[0]}/{parts[1]}/{parts[3][:-1]}"
