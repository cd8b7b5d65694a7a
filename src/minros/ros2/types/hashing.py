"""Type descriptions and RIHS01 type hashes (REP-2011), as rosidl_generator_type_description
computes them.

A type's *individual* description lists its fields: name, a field type id (the constants of
type_description_interfaces/msg/FieldType: the value type's id, plus 48 for a fixed array, 96
for a bounded and 144 for an unbounded sequence), capacity (array length or bound), string
capacity (``string<=N``) and the nested type's name. The *full* description is the type's own
plus those of every type it references, directly or not, sorted by name. The hash is
``RIHS01_`` + the SHA-256 of the full description as JSON without the default values, written
with ``", "`` and ``": "`` separators, keys in that order, ASCII only.

Services and actions are described as structs too: ``pkg/srv/Name`` has members
``request_message``, ``response_message``, ``event_message``; ``pkg/action/Name`` has ``goal``,
``result``, ``feedback``, ``send_goal_service``, ``get_result_service``, ``feedback_message``.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any, Callable, Dict, List, Set

from .model import ARRAY, BOUNDED, SCALAR, SEQUENCE, FieldType, MessageType

#: type_description_interfaces/msg/FieldType: the ids of the value types
VALUE_TYPE_ID = {
    "int8": 2, "uint8": 3, "char": 3,  # a .msg char is IDL uint8
    "int16": 4, "uint16": 5, "int32": 6, "uint32": 7, "int64": 8, "uint64": 9,
    "float32": 10, "float64": 11, "bool": 15, "byte": 16, "string": 17, "wstring": 18,
}
NESTED_TYPE_ID = 1
BOUNDED_STRING_TYPE_ID = {"string": 21, "wstring": 22}
ARRAY_OFFSET = {SCALAR: 0, ARRAY: 48, BOUNDED: 96, SEQUENCE: 144}

RIHS01_PREFIX = "RIHS01_"

Description = Dict[str, Any]
GetType = Callable[[str], MessageType]


def field_type_id(type_: FieldType) -> int:
    if type_.is_nested:
        value = NESTED_TYPE_ID
    elif type_.string_bound:
        value = BOUNDED_STRING_TYPE_ID[type_.base]
    else:
        value = VALUE_TYPE_ID[type_.base]
    return value + ARRAY_OFFSET[type_.kind]


def individual_description(struct: MessageType) -> Description:
    """One type's description: ``{"type_name", "fields": [...]}`` with default values."""
    return {
        "type_name": struct.name,
        "fields": [{
            "name": f.name,
            "type": {
                "type_id": field_type_id(f.type),
                "capacity": f.type.size if f.type.kind in (ARRAY, BOUNDED) else 0,
                "string_capacity": f.type.string_bound,
                "nested_type_name": f.type.base if f.type.is_nested else "",
            },
            "default_value": f.default_text,
        } for f in struct.fields],
    }


def referenced_types(name: str, get_type: GetType) -> List[str]:
    """Every type ``name`` refers to, directly or not, sorted by name."""
    seen: Set[str] = set()
    pending = get_type(name).dependencies()
    while pending:
        dep = pending.pop()
        if dep in seen:
            continue
        seen.add(dep)
        pending.extend(get_type(dep).dependencies())
    return sorted(seen)


def type_description(name: str, get_type: GetType) -> Description:
    """The full description, as in the ``type_description_msg`` of rosidl's JSON files."""
    return {
        "type_description": individual_description(get_type(name)),
        "referenced_type_descriptions": [individual_description(get_type(dep))
                                         for dep in referenced_types(name, get_type)],
    }


def rihs01(description: Description) -> str:
    """The RIHS01 hash string of a full type description."""
    def hashable(individual: Description) -> Description:
        return {"type_name": individual["type_name"],
                "fields": [{"name": f["name"], "type": f["type"]} for f in individual["fields"]]}

    text = json.dumps({
        "type_description": hashable(description["type_description"]),
        "referenced_type_descriptions": [hashable(d) for d in
                                         description["referenced_type_descriptions"]],
    }, ensure_ascii=True, separators=(", ", ": "), sort_keys=False)
    return RIHS01_PREFIX + hashlib.sha256(text.encode("utf-8")).hexdigest()


def type_hash(name: str, get_type: GetType) -> str:
    """RIHS01 hash of type ``name``; ``get_type`` resolves it and every type it references."""
    return rihs01(type_description(name, get_type))
