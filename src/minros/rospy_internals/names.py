"""rospy.names: the node's name and remappings, name resolution and name validators, with
rospy's names, over minros's default node.

``rospy.names`` *is* this module; its globals ``_mappings``, ``_resolved_mappings``,
``_caller_id`` and ``_caller_namespace`` are properties reading and setting the node's.
"""

from __future__ import annotations

import sys
import types
from typing import Any, Dict, Optional

from minros import names as _names
from minros import node as _node
from minros.exceptions import ROSException, ROSInitException  # noqa: F401
from minros.names import (  # noqa: F401 - rospy.names' namespace has them
    ANYTYPE,
    GLOBALNS,
    REMAP,
    SEP,
    SERVICE_ANYTYPE,
    TOPIC_ANYTYPE,
    canonicalize_name,
    get_ros_namespace,
    is_global,
    is_private,
    load_mappings,
    make_global_ns,
    namespace,
    ns_join,
)
from minros.wire.rosapi import (  # noqa: F401
    ParameterInvalid,
    global_name,
    valid_name,
    valid_name_validator_resolved,
    valid_name_validator_unresolved,
)


def isstring(s: Any) -> bool:
    """True for a str (rospy's Python 2/3 string test)."""
    return isinstance(s, str)


def reload_mappings(argv: Any) -> None:
    """Read the remapping table again from ``argv``."""
    _node.default_node().names.argv_mappings = load_mappings(argv)


def initialize_mappings(node_name: str) -> None:
    """Resolve the remappings for node ``node_name``."""
    names = _node.default_node().names
    names.resolved_mappings = _names.resolve_mappings(names.argv_mappings, node_name)


def resolve_name_without_node_name(name: str) -> str:
    """A topic or service name made before init_node (ValueError for ``~name``)."""
    return _node.default_node().resolve_name_without_node_name(name)


def get_mappings() -> Dict[str, str]:
    """The command line's remappings, unresolved."""
    return _node.default_node().names.argv_mappings


def get_resolved_mappings() -> Dict[str, str]:
    """The remappings resolved for the node (after init_node)."""
    return _node.default_node().names.resolved_mappings


def resolve_name(name: str, caller_id: Optional[str] = None) -> str:
    """``name`` resolved relative to ``caller_id`` (default: this node), then remapped."""
    if not caller_id:
        caller_id = get_name()
    if not name:
        return namespace(caller_id)
    name = canonicalize_name(str(name))
    if name[0] == SEP:
        resolved = name
    elif is_private(name):
        resolved = canonicalize_name(caller_id + SEP + name[1:])
    else:
        resolved = namespace(caller_id) + name
    return get_resolved_mappings().get(resolved, resolved)


def remap_name(name: str, caller_id: Optional[str] = None, resolved: bool = True) -> str:
    """``name`` remapped (and then resolved), or unchanged when it is not remapped."""
    return _node.remap_name(name, caller_id or None)


def scoped_name(caller_id: str, name: str) -> str:
    """``name`` relative to the namespace of ``caller_id`` (a global name)."""
    if not is_global(caller_id):
        raise ROSException("caller_id must be global")
    return canonicalize_name(name)[len(namespace(caller_id)):]


def get_namespace() -> str:
    return _node.get_namespace()


def get_name() -> str:
    return _node.get_caller_id()


get_caller_id = get_name


def _set_caller_id(caller_id: str) -> None:
    """Name the node (rospy's internal API; init_node does it for a real node)."""
    _node.default_node().names.caller_id = caller_id


class _NamesModule(types.ModuleType):
    @property
    def _mappings(self) -> Dict[str, str]:
        return get_mappings()

    @_mappings.setter
    def _mappings(self, value: Dict[str, str]) -> None:
        _node.default_node().names.argv_mappings = value

    @property
    def _resolved_mappings(self) -> Dict[str, str]:
        return get_resolved_mappings()

    @_resolved_mappings.setter
    def _resolved_mappings(self, value: Dict[str, str]) -> None:
        _node.default_node().names.resolved_mappings = value

    @property
    def _caller_id(self) -> str:
        return get_name()

    @_caller_id.setter
    def _caller_id(self, value: str) -> None:
        _set_caller_id(value)

    @property
    def _caller_namespace(self) -> str:
        return get_namespace()


sys.modules[__name__].__class__ = _NamesModule

#: what ``from rospy.names import *`` gives: rospy.names' public names
__all__ = ["ANYTYPE", "GLOBALNS", "ParameterInvalid", "REMAP", "ROSException", "ROSInitException",
           "SEP", "SERVICE_ANYTYPE", "TOPIC_ANYTYPE", "canonicalize_name", "get_caller_id",
           "get_mappings", "get_name", "get_namespace", "get_resolved_mappings",
           "get_ros_namespace", "global_name", "initialize_mappings", "is_global", "is_private",
           "isstring", "load_mappings", "make_global_ns", "namespace", "ns_join",
           "reload_mappings", "remap_name", "resolve_name", "resolve_name_without_node_name",
           "scoped_name", "valid_name", "valid_name_validator_resolved",
           "valid_name_validator_unresolved"]
