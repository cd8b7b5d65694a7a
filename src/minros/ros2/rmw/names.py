"""ROS 2 names on DDS, as rmw maps them (rmw_fastrtps, rmw_cyclonedds, rmw_dds_common).

* A topic ``/chatter`` is the DDS topic ``rt/chatter``; a service ``/add`` is two topics,
  ``rq/addRequest`` (requests) and ``rr/addReply`` (replies). A QoS with
  ``avoid_ros_namespace_conventions`` uses the bare name (``chatter``).
* A message type ``std_msgs/msg/String`` is the DDS type ``std_msgs::msg::dds_::String_``;
  a service type ``std_srvs/srv/SetBool`` has ``std_srvs::srv::dds_::SetBool_Request_`` and
  ``std_srvs::srv::dds_::SetBool_Response_``.
* Names are resolved as rcl resolves them: relative to the node's namespace, ``~`` to the
  node's own name.
"""

from __future__ import annotations

import re
from typing import Optional, Tuple

__all__ = [
    "NameError_", "dds_to_topic", "dds_to_type", "resolve", "service_topics", "service_types",
    "topic_to_dds", "type_to_dds", "validate_node_name", "validate_namespace",
]

TOPIC_PREFIX = "rt"
REQUEST_PREFIX = "rq"
REPLY_PREFIX = "rr"

_TOKEN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_NODE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class NameError_(ValueError):
    """A ROS 2 name that rcl would refuse; ``str()`` says which rule it breaks."""


def validate_node_name(name: str) -> None:
    if not _NODE.match(name):
        raise NameError_(f"node name {name!r}: letters, digits and underscores, not starting "
                         "with a digit")


def validate_namespace(namespace: str) -> str:
    """The namespace as rcl keeps it ('/' or '/a/b'); raises NameError_."""
    if not namespace:
        return "/"
    if not namespace.startswith("/"):
        namespace = "/" + namespace
    if namespace != "/":
        namespace = namespace.rstrip("/")
        for token in namespace[1:].split("/"):
            if not _TOKEN.match(token):
                raise NameError_(f"namespace {namespace!r}: {token!r} is not a valid token")
    return namespace


def resolve(name: str, namespace: str = "/", node: Optional[str] = None) -> str:
    """A topic or service name made fully qualified (``chatter`` in ``/robot`` ->
    ``/robot/chatter``; ``~/status`` of node ``cam`` -> ``/robot/cam/status``)."""
    if not name:
        raise NameError_("an empty topic or service name")
    if name.startswith("~"):
        if node is None:
            raise NameError_(f"{name!r}: '~' needs a node name")
        base = namespace.rstrip("/") + "/" + node
        name = base + name[1:]
    elif not name.startswith("/"):
        name = namespace.rstrip("/") + "/" + name
    name = re.sub("/+", "/", name)
    if len(name) > 1:
        name = name.rstrip("/")
    for token in name[1:].split("/"):
        if not _TOKEN.match(token):
            raise NameError_(f"topic or service name {name!r}: {token!r} is not a valid token")
    return name


def topic_to_dds(name: str, prefix: str = TOPIC_PREFIX, suffix: str = "",
                 avoid_ros_namespace_conventions: bool = False) -> str:
    """``/chatter`` -> ``rt/chatter`` (``rq/...Request``, ``rr/...Reply`` for services)."""
    if avoid_ros_namespace_conventions:
        return name.lstrip("/") + suffix
    return prefix + name + suffix


def service_topics(name: str, avoid_ros_namespace_conventions: bool = False) -> Tuple[str, str]:
    """The request and reply topics of service ``name``."""
    return (topic_to_dds(name, REQUEST_PREFIX, "Request", avoid_ros_namespace_conventions),
            topic_to_dds(name, REPLY_PREFIX, "Reply", avoid_ros_namespace_conventions))


def dds_to_topic(dds_name: str) -> Optional[Tuple[str, str]]:
    """``rt/chatter`` -> (``/chatter``, "topic"); ``rq/addRequest`` -> (``/add``, "request");
    ``rr/addReply`` -> (``/add``, "reply"); None for a name outside rmw's conventions."""
    if dds_name.startswith("rt/"):
        return dds_name[2:], "topic"
    if dds_name.startswith("rq/") and dds_name.endswith("Request"):
        return dds_name[2:-len("Request")], "request"
    if dds_name.startswith("rr/") and dds_name.endswith("Reply"):
        return dds_name[2:-len("Reply")], "reply"
    return None


def _split_type(type_name: str) -> Tuple[str, str, str]:
    parts = type_name.split("/")
    if len(parts) == 2:  # pkg/Name: a message
        parts = [parts[0], "msg", parts[1]]
    if len(parts) != 3 or not all(_TOKEN.match(x) for x in parts):
        raise NameError_(f"type {type_name!r}: expected package/msg/Name")
    return parts[0], parts[1], parts[2]


def type_to_dds(type_name: str) -> str:
    """``std_msgs/msg/String`` -> ``std_msgs::msg::dds_::String_``."""
    pkg, kind, name = _split_type(type_name)
    return f"{pkg}::{kind}::dds_::{name}_"


def service_types(type_name: str) -> Tuple[str, str]:
    """``std_srvs/srv/SetBool`` -> its request and response DDS types."""
    pkg, kind, name = _split_type(type_name)
    if kind == "msg":
        kind = "srv"
    return (f"{pkg}::{kind}::dds_::{name}_Request_", f"{pkg}::{kind}::dds_::{name}_Response_")


def dds_to_type(dds_type: str) -> Optional[str]:
    """``std_msgs::msg::dds_::String_`` -> ``std_msgs/msg/String`` (a service's request or
    response type -> ``pkg/srv/Name``); None for a type outside rmw's conventions."""
    parts = dds_type.split("::")
    if len(parts) != 4 or parts[2] != "dds_" or not parts[3].endswith("_"):
        return None
    name = parts[3][:-1]
    if parts[1] == "srv":
        for tail in ("_Request", "_Response"):
            if name.endswith(tail):
                name = name[:-len(tail)]
                break
    return f"{parts[0]}/{parts[1]}/{name}"


def type_hash_user_data(type_hash: Optional[str], extra: str = "") -> bytes:
    """USER_DATA of an endpoint: ``typehash=RIHS01_...;`` (rmw_dds_common's encoding), then
    ``extra`` (``clientid=...;``)."""
    text = f"typehash={type_hash};" if type_hash else ""
    return (text + extra).encode()
