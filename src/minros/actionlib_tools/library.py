"""actionlib_tools.library: messages from and to YAML (the helpers ROS's axclient uses)."""

from __future__ import annotations

from typing import Any, List, Optional

import yaml

from minros import packages
from minros.exceptions import ROSException
from minros.msgs.fill import fill_message_args
from minros.msgs.message import Message, strify_message

__all__ = ["findros", "YAMLBag", "to_yaml", "yaml_msg_str", "yaml_msg", "yaml_msgs_str",
           "yaml_msgs"]


def findros(pkg: str, resource: str) -> str:
    """The first file called ``resource`` inside package ``pkg``."""
    found = packages.find_resource(pkg, resource)
    if not found:
        raise ROSException(f"cannot find resource {resource} in package {pkg}")
    return found[0]


def to_yaml(obj: Any) -> str:
    return strify_message(obj) if isinstance(obj, Message) else yaml.dump(obj)


class YAMLBag:
    """Messages written one after another as YAML text."""

    def __init__(self, filename: str) -> None:
        self.filename = filename
        self._fp: Optional[Any] = open(filename, "w")  # noqa: SIM115 - closed by close()

    def append(self, msg: Any) -> None:
        if self._fp is None:
            raise ValueError(f"YAMLBag {self.filename} is closed")
        self._fp.write(to_yaml(msg))

    def close(self) -> None:
        if self._fp is not None:
            self._fp.close()
            self._fp = None


def yaml_msg_str(type_: type, yaml_str: str, filename: Optional[str] = None) -> Any:
    """One message of class ``type_`` from a YAML dictionary."""
    msg_dict = {} if yaml_str.strip() == "" else yaml.safe_load(yaml_str)
    if not isinstance(msg_dict, dict):
        where = f"yaml file [{filename}]" if filename else "yaml string"
        raise ValueError(f"{where} does not contain a dictionary")
    msg = type_()
    fill_message_args(msg, [msg_dict])
    return msg


def yaml_msg(type_: type, filename: str) -> Any:
    with open(filename) as f:
        return yaml_msg_str(type_, f.read(), filename=filename)


def yaml_msgs_str(type_: type, yaml_str: str, filename: Optional[str] = None) -> List[Any]:
    """Messages of class ``type_`` from a YAML list of dictionaries."""
    doc = yaml.safe_load(yaml_str) or []
    msgs = []
    for msg_dict in doc:
        if not isinstance(msg_dict, dict):
            where = f"yaml file [{filename}]" if filename else "yaml string"
            raise ValueError(f"{where} does not contain a list of dictionaries")
        msg = type_()
        fill_message_args(msg, [msg_dict])
        msgs.append(msg)
    return msgs


def yaml_msgs(type_: type, filename: str) -> List[Any]:
    with open(filename) as f:
        return yaml_msgs_str(type_, f.read(), filename=filename)
