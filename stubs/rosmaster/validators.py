"""rosmaster.validators: the argument checks of the master's API (minros.wire.rosapi)."""

from minros.wire.rosapi import (  # noqa: F401
    ParameterInvalid,
    empty_or_valid_name,
    global_name,
    is_api,
    is_service,
    is_topic,
    non_empty,
    non_empty_str,
    not_none,
    valid_name,
    valid_name_validator_resolved,
    valid_name_validator_unresolved,
    valid_type_name,
)


def isstring(s: object) -> bool:
    return isinstance(s, str)

from rosgraph.names import resolve_name  # noqa: E402, F401

ANYTYPE = "*"
ROSRPC = "rosrpc://"
TYPE_SEPARATOR = "/"
