"""The key expressions of zenoh-plugin-ros1 (``zenoh-bridge-ros1``), and minros's own.

Facts from zenoh-plugin-ros1 (``topic_utilities.rs``, ``discovery.rs``, after its PR #225):

- data: ``<hex of the type name>/<md5sum>/<bridge namespace>/<topic>``, the topic (or
  service) name without its leading and trailing ``/``; a service uses its service type and
  service md5sum. The payload is the serialized message without TCPROS's 4-byte length.
- discovery: ``ros1_discovery_info/<discovery namespace>/<class>/<hex type>/<md5>/<bridge
  namespace>/<topic>``, class ``pub``, ``sub``, ``srv`` or ``cl``; the discovery namespace is
  always ``*``; the bridge namespace is ``*`` unless the bridge was given one.

A bridge publishes and subscribes data under its own bridge namespace: ``*`` (the default)
reaches every namespace, a name reaches bridges of that name and of ``*``.

minros adds keys of its own under ``minros_ros1/``, which zenoh-bridge-ros1 never subscribes
to: ``minros_ros1/topic/<hex>/<md5>/<ns>/<topic>`` is the queryable a minros bridge answers
about a topic it publishes (definition, latching, the latched message: see ``meta``).
"""

from __future__ import annotations

import binascii
import re
from dataclasses import dataclass

__all__ = [
    "CLASSES", "DEFAULT_NAMESPACE", "DISCOVERY_PREFIX", "KeyMappingError", "Resource", "check_namespace",
    "data_key", "discovery_key", "discovery_subscription", "meta_key", "parse_discovery_key",
    "topic_chunk", "type_hex",
]

#: the bridge namespace that matches every other
DEFAULT_NAMESPACE = "*"
DISCOVERY_PREFIX = "ros1_discovery_info"
#: zenoh-plugin-ros1's discovery namespace, always "*"
DISCOVERY_NAMESPACE = "*"
#: resource classes of the discovery keys: a ROS publisher, subscriber, service, service client
CLASSES = ("pub", "sub", "srv", "cl")
META_PREFIX = "minros_ros1/topic"

# a ROS graph resource name, as key chunks: letters, digits, '_' (rosgraph's legal names), '~'
# never reaches here (names are resolved); Zenoh forbids '*', '$', '?', '#' and empty chunks
_NAME_CHUNK = re.compile(r"^[A-Za-z0-9_]+$")
_HEX = re.compile(r"^(?:[0-9a-f]{2})+$")
_MD5 = re.compile(r"^[0-9a-f]{32}$")
_NAMESPACE = re.compile(r"^(?:\*|[A-Za-z0-9_\-]+)$")
_TYPE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*/[A-Za-z][A-Za-z0-9_]*$")


class KeyMappingError(ValueError):
    """A key expression or name that cannot be mapped; the text says what is wrong."""


@dataclass(frozen=True, order=True)
class Resource:
    """One ROS resource as the beacons name it: ``kind`` is a CLASSES entry, ``name`` a
    global ROS name, ``type`` a message type (topics) or service type (``srv``, ``cl``)."""

    kind: str
    name: str
    type: str
    md5sum: str
    namespace: str = DEFAULT_NAMESPACE

    @property
    def topic(self) -> tuple:
        """What identifies the data: name, type and md5sum (not who declared it)."""
        return (self.name, self.type, self.md5sum)


def type_hex(type_name: str) -> str:
    """``std_msgs/String`` -> ``7374645f6d7367732f537472696e67`` (the bytes of the name in
    lower-case hex, as the bridge's ``hex::encode``)."""
    return type_name.encode("utf-8").hex()


def topic_chunk(name: str) -> str:
    """The topic part of a key: the ROS name without its leading and trailing '/'."""
    chunk = name.strip("/")
    parts = chunk.split("/")
    if not chunk or not all(_NAME_CHUNK.match(p) for p in parts):
        raise KeyMappingError(f"[{name}] is not a ROS graph name that maps to a Zenoh key")
    return chunk


def check_namespace(namespace: str) -> str:
    """A bridge namespace: ``*`` or one key chunk of letters, digits, '_' and '-'."""
    if not _NAMESPACE.match(namespace or ""):
        raise KeyMappingError(f"bridge namespace [{namespace}] must be '*' or one word of letters, "
                        "digits, '_' and '-' (no '/')")
    return namespace


def _check_type(type_name: str, md5sum: str) -> None:
    if not _TYPE.match(type_name):
        raise KeyMappingError(f"[{type_name}] is not a ROS type name (package/Name)")
    if not _MD5.match(md5sum):
        raise KeyMappingError(f"[{md5sum}] is not an md5sum (32 lower-case hex digits)")


def data_key(name: str, type_name: str, md5sum: str,
             namespace: str = DEFAULT_NAMESPACE) -> str:
    """The key a topic's messages (or a service's queries) travel under."""
    _check_type(type_name, md5sum)
    return f"{type_hex(type_name)}/{md5sum}/{check_namespace(namespace)}/{topic_chunk(name)}"


def discovery_key(kind: str, name: str, type_name: str, md5sum: str,
                  namespace: str = DEFAULT_NAMESPACE) -> str:
    """The key of the beacon that declares a resource."""
    if kind not in CLASSES:
        raise KeyMappingError(f"resource class [{kind}] is not one of {', '.join(CLASSES)}")
    return f"{DISCOVERY_PREFIX}/{DISCOVERY_NAMESPACE}/{kind}/" + data_key(
        name, type_name, md5sum, namespace)


def discovery_subscription(namespace: str = DEFAULT_NAMESPACE) -> str:
    """What a bridge in ``namespace`` listens to for beacons (as zenoh-plugin-ros1 does)."""
    return f"{DISCOVERY_PREFIX}/*/*/*/*/{check_namespace(namespace)}/*/**"


def meta_key(name: str, type_name: str, md5sum: str, namespace: str = DEFAULT_NAMESPACE) -> str:
    """minros's queryable about a published topic (see ``meta``)."""
    return f"{META_PREFIX}/" + data_key(name, type_name, md5sum, namespace)


def parse_discovery_key(key: str) -> Resource:
    """The resource a beacon's key declares; KeyMappingError saying what is wrong otherwise."""
    parts = str(key).split("/")
    if len(parts) < 7 or parts[0] != DISCOVERY_PREFIX:
        raise KeyMappingError(f"not a discovery key: [{key}]")
    kind, hex_type, md5sum, namespace = parts[2], parts[3], parts[4], parts[5]
    if kind not in CLASSES:
        raise KeyMappingError(f"unknown resource class [{kind}] in [{key}]")
    if not _HEX.match(hex_type):
        raise KeyMappingError(f"type [{hex_type}] is not hex in [{key}]")
    try:
        type_name = binascii.unhexlify(hex_type).decode("utf-8")
    except UnicodeDecodeError:
        raise KeyMappingError(f"type [{hex_type}] is not UTF-8 in [{key}]") from None
    try:
        _check_type(type_name, md5sum)
        check_namespace(namespace)
        name = "/" + topic_chunk("/".join(parts[6:]))
    except KeyMappingError as exc:
        raise KeyMappingError(f"{exc} in [{key}]") from None
    return Resource(kind, name, type_name, md5sum, namespace)
