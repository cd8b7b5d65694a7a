"""Configurations <-> dynamic_reconfigure messages (pure functions, no ROS connection).

A configuration is a :class:`Config` (a dict with attribute access) mapping parameter names to
values, plus optionally ``groups``: the group tree with each group's state. On the wire it is a
``dynamic_reconfigure/Config``: one list per value type (bools, ints, strs, doubles) and a flat
list of ``GroupState``. A configuration type (the generated ``<Name>Config`` module) is described
by a ``ConfigDescription``: the groups with their parameters, and the min, max and default
configurations. These functions produce the same messages and dicts as ROS 1's.
"""

from __future__ import annotations

import copy
from typing import Any, Callable, Dict, Iterable, List

from dynamic_reconfigure.msg import (
    BoolParameter,
    DoubleParameter,
    GroupState,
    IntParameter,
    ParamDescription,
    StrParameter,
)
from dynamic_reconfigure.msg import Config as ConfigMsg
from dynamic_reconfigure.msg import ConfigDescription as ConfigDescrMsg
from dynamic_reconfigure.msg import Group as GroupMsg


class Config(dict):
    """A dict whose keys are also attributes (``config.int_param``)."""

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def __setattr__(self, name: str, value: Any) -> None:
        self[name] = value

    def __delattr__(self, name: str) -> None:
        del self[name]

    def __getstate__(self) -> list:
        return list(self.__dict__.items())

    def __setstate__(self, items: list) -> None:
        for key, value in items:
            self.__dict__[key] = value

    def copy(self) -> Config:
        return Config(self)

    def __deepcopy__(self, memo: dict) -> Config:
        return type(self)({copy.deepcopy(k, memo): copy.deepcopy(v, memo) for k, v in self.items()})


# dynparam dump files name the type by its ROS module (python/object/new:...encoding.Config):
# give it that name, which the stand-in package serves, so dumps load in either ROS
Config.__module__ = "dynamic_reconfigure.encoding"


def _values(msg: Any) -> Config:
    """The name -> value pairs of a Config message, in ROS's order: bools, ints, strs, doubles."""
    return Config([(kv.name, kv.value) for kv in (*msg.bools, *msg.ints, *msg.strs, *msg.doubles)])


def encode_description(descr: Any) -> Any:
    """The ConfigDescription of a configuration type (a generated ``<Name>Config`` module)."""
    msg = ConfigDescrMsg()
    msg.max = encode_config(descr.max)
    msg.min = encode_config(descr.min)
    msg.dflt = encode_config(descr.defaults)
    msg.groups = encode_groups(None, descr.config_description)
    return msg


def encode_groups(parent: Any, group: Dict[str, Any]) -> List[Any]:
    """The group tree ``group`` as a flat list of Group messages, parents before children."""
    msg = GroupMsg()
    msg.name = group["name"]
    msg.id = group["id"]
    msg.parent = group["parent"]
    msg.type = group["type"]
    msg.parameters = [ParamDescription(p["name"], p["type"], p["level"], p["description"],
                                       p["edit_method"]) for p in group["parameters"]]
    out = [msg]
    for child in group["groups"]:
        out.extend(encode_groups(msg, child))
    return out


def _group_states(tree: Dict[str, Any]) -> List[Any]:
    """The subgroups of ``tree``, each after its own subgroups."""
    out = []
    for child in tree["groups"].values():
        out.extend(_group_states(child))
        out.append(GroupState(child["name"], child["state"], child["id"], child["parent"]))
    return out


def encode_config(config: Dict[str, Any], flat: bool = True) -> Any:
    """A Config message from a configuration dict (values of other types are left out)."""
    msg = ConfigMsg()
    for key, value in config.items():
        kind = type(value)
        if kind is int:
            msg.ints.append(IntParameter(key, value))
        elif kind is bool:
            msg.bools.append(BoolParameter(key, value))
        elif kind is str:
            msg.strs.append(StrParameter(key, value))
        elif kind is float:
            msg.doubles.append(DoubleParameter(key, value))
        elif kind is dict or isinstance(value, Config):
            if flat:
                msg.groups.append(GroupState(value["name"], value["state"], value["id"],
                                             value["parent"]))
                msg.groups.extend(_group_states(value))
            else:
                msg.groups = [GroupState(g["name"], g["state"], g["id"], g["parent"]) for g in value]
    return msg


def group_dict(group: Any) -> Config:
    """A tree node for a Group or GroupState message (state True / type '' when absent)."""
    return Config({
        "id": group.id, "parent": group.parent, "name": group.name,
        "type": getattr(group, "type", ""), "state": getattr(group, "state", True),
        "groups": Config({}), "parameters": Config({}),
    })


def _root(groups: Iterable[Any]) -> Any:
    root = None
    for group in groups:
        if group.id == 0:
            root = group
    return root


def _children(groups: List[Any], parent_id: int, seen: set) -> List[Any]:
    """The groups whose parent is ``parent_id``; ``seen`` stops a peer's cyclic tree."""
    out = []
    for group in groups:
        if group.id != 0 and group.parent == parent_id and group.id not in seen:
            out.append(group)
    return out


def _no_fill(node: Config, group: Any) -> None:
    pass


def _subtree(groups: List[Any], parent_id: int, seen: set,
             fill: Callable[[Config, Any], None] = _no_fill) -> Config:
    """The tree nodes of the groups below ``parent_id``, by name; ``fill(node, group)``
    completes each node from its message before its own subgroups are added."""
    children = Config({})
    for group in _children(groups, parent_id, seen):
        node = group_dict(group)
        fill(node, group)
        node["groups"] = _subtree(groups, group.id, seen | {group.id}, fill)
        children[node["name"]] = node
    return children


def _add_values(node: Dict[str, Any], descr: Dict[str, Any],
                put: Callable[[Dict[str, Any], str], None]) -> None:
    """``put(group node, parameter name)`` for every parameter of the description, walking
    the tree and the description side by side (subgroups matched by name)."""
    for param in descr["parameters"]:
        put(node, param["name"])
    for child in node["groups"].values():
        for sub in _sub_descriptions(descr):
            if sub["name"] == child["name"]:
                _add_values(child, sub, put)


def decode_description(msg: Any) -> Config:
    """The group tree of a ConfigDescription, with each parameter's min, max and default."""
    mins, maxes, defaults = decode_config(msg.min), decode_config(msg.max), decode_config(msg.dflt)

    def params_of(group: Any) -> List[Dict[str, Any]]:
        return [{"name": p.name, "min": mins[p.name], "max": maxes[p.name],
                 "default": defaults[p.name], "type": p.type, "level": p.level,
                 "description": p.description, "edit_method": p.edit_method}
                for p in group.parameters]

    def fill(node: Config, group: Any) -> None:
        node["parameters"] = params_of(group)

    root_msg = _root(msg.groups)
    tree: Any = {}
    if root_msg is not None:
        tree = group_dict(root_msg)
        fill(tree, root_msg)
        tree["groups"] = _subtree(msg.groups, tree["id"], {0}, fill)
    return tree


def get_tree(m: Any, group: Any = None) -> Any:
    """The group tree (without parameters) of a message that has ``groups``."""
    if group is None:
        group = _root(m.groups)
    if group.id != 0:
        return _subtree(m.groups, group.id, {0, group.id})
    tree = group_dict(group)
    tree["groups"] = _subtree(m.groups, 0, {0})
    return tree


def _first_child_state(node: Dict[str, Any], description: Dict[str, Any]) -> None:
    """Copy the state of the description's group with ``node``'s id into ``node``.

    ROS follows only the first subgroup at each level of the description, so a group off that
    path keeps the state from the message; kept as is, since servers rely on the result.
    """
    for group in description["groups"]:
        if group["id"] == node["id"]:
            node["state"] = group["state"]
        else:
            _first_child_state(node, group)
        return


def _sub_descriptions(description: Dict[str, Any]) -> Iterable[Dict[str, Any]]:
    groups = description["groups"]
    return groups.values() if isinstance(groups, dict) else groups


def initial_config(msg: Any, description: Dict[str, Any] | None = None) -> Config:
    """A server's starting configuration: values of ``msg``, group states of ``description``."""
    config = _values(msg)
    if not msg.groups or description is None:
        return config

    tree = group_dict(_root(msg.groups))
    tree["groups"] = _subtree(msg.groups, 0, {0},
                              lambda node, group: _first_child_state(node, description))
    config["groups"] = tree

    def put(node: Dict[str, Any], name: str) -> None:
        node["parameters"][name] = config[name]

    _add_values(tree, description, put)
    return config


def decode_config(msg: Any, description: Dict[str, Any] | None = None) -> Config:
    """The configuration a Config message carries; with a description, its groups too (each
    group node also holds its parameters' values under their names)."""
    config = _values(msg)
    if not msg.groups or description is None:
        return config
    config["groups"] = get_tree(msg)

    def put(node: Dict[str, Any], name: str) -> None:
        if name in config:
            node[name] = config[name]

    _add_values(config["groups"], description, put)
    return config


def extract_params(group: Dict[str, Any]) -> List[Any]:
    """Every parameter of a group tree, the group's own first, then depth first."""
    params = list(group["parameters"])
    for child in _sub_descriptions(group):
        params.extend(extract_params(child))
    return params


def get_parents(group: Dict[str, Any], descriptions: Dict[str, Any]) -> List[Dict[str, Any]]:
    """The ancestors of ``group`` in ``descriptions['group']``, root first."""
    parents = []
    for candidate in descriptions["group"]:
        if candidate["id"] == group["parent"]:
            parents.extend(get_parents(candidate, descriptions))
            parents.append(candidate)
    return parents
