"""ROS 2's graph without I/O: ``ros_discovery_info`` samples and the tables rclpy's graph
queries read.

DDS knows participants and endpoints; ROS 2 knows nodes. rmw bridges the two with the topic
``ros_discovery_info`` (type ``rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_``): each
participant publishes, transient-local, which nodes it holds and the GUIDs ("gids") of each
node's readers and writers. rclpy's ``get_node_names_and_namespaces()`` is those samples;
``get_topic_names_and_types()`` is SEDP's endpoints; ``get_publishers_info_by_topic()`` joins
both (an endpoint's node is the node whose list holds its gid).

The CDR of ``ParticipantEntitiesInfo`` (``Gid`` is ``uint8[16]`` in Jazzy and Kilted)::

    gid[16]  uint32 n  n * { string namespace  string name
                             uint32 r  r * gid[16]   uint32 w  w * gid[16] }
"""

from __future__ import annotations

import struct
import threading
import time
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Set, Tuple

from minros.ros2.rmw import names
from minros.ros2.rmw.qos import QoSProfile, from_dds
from minros.ros2.rtps.discovery import EndpointData

__all__ = ["DISCOVERY_TOPIC", "DISCOVERY_TYPE", "DISCOVERY_TYPE_HASH", "EndpointInfo", "Graph",
           "GraphError", "NodeEntities", "decode_participant_info", "encode_participant_info"]

DISCOVERY_TOPIC = "ros_discovery_info"
DISCOVERY_TYPE = "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"
#: RIHS01 of rmw_dds_common/msg/ParticipantEntitiesInfo (the pip ROS 2's JSON)
DISCOVERY_TYPE_HASH = "RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e"
GID_SIZE = 16
#: rmw_dds_common's bounds: node names and namespaces are string<=256
MAX_NAME = 256


class GraphError(ValueError):
    """A ``ros_discovery_info`` sample that does not decode."""


@dataclass
class NodeEntities:
    namespace: str
    name: str
    readers: List[bytes] = field(default_factory=list)
    writers: List[bytes] = field(default_factory=list)


def encode_participant_info(gid: bytes, nodes: List[NodeEntities]) -> bytes:
    """A ParticipantEntitiesInfo sample (CDR little-endian, encapsulation header first)."""
    out = bytearray(b"\x00\x01\x00\x00")
    out += gid.ljust(GID_SIZE, b"\0")[:GID_SIZE]

    def align4() -> None:
        out.extend(b"\0" * (-(len(out) - 4) % 4))

    def string(text: str) -> None:
        raw = text.encode() + b"\0"
        align4()
        out.extend(struct.pack("<I", len(raw)) + raw)

    align4()
    out += struct.pack("<I", len(nodes))
    for node in nodes:
        string(node.namespace)
        string(node.name)
        for gids in (node.readers, node.writers):
            align4()
            out += struct.pack("<I", len(gids))
            for x in gids:
                out += x.ljust(GID_SIZE, b"\0")[:GID_SIZE]
    return bytes(out)


def decode_participant_info(payload: bytes) -> Tuple[bytes, List[NodeEntities]]:
    """(participant gid, nodes) of a sample. Raises GraphError for one that does not decode
    (each count is checked against the bytes that are there before anything is built)."""
    view = memoryview(payload)
    if len(view) < 4 + GID_SIZE + 4:
        raise GraphError(f"a ParticipantEntitiesInfo of {len(view)} bytes")
    little = view[1] & 1 == 1
    u32 = struct.Struct("<I" if little else ">I")
    pos = 4

    def align4() -> None:
        nonlocal pos
        pos += -(pos - 4) % 4

    def count(per_item: int) -> int:
        nonlocal pos
        align4()
        if pos + 4 > len(view):
            raise GraphError("a ParticipantEntitiesInfo cut short")
        (n,) = u32.unpack_from(view, pos)
        pos += 4
        if n * per_item > len(view) - pos:
            raise GraphError(f"a sequence of {n} in {len(view) - pos} bytes")
        return int(n)

    def string() -> str:
        nonlocal pos
        n = count(1)
        if n < 1 or n > MAX_NAME + 1:
            raise GraphError(f"a name of {n} bytes (at most {MAX_NAME})")
        raw = bytes(view[pos:pos + n])
        pos += n
        if raw[-1:] != b"\0":
            raise GraphError("a name without its NUL")
        try:
            return raw[:-1].decode()
        except UnicodeDecodeError:
            raise GraphError("a name that is not UTF-8") from None

    def gids() -> List[bytes]:
        nonlocal pos
        n = count(GID_SIZE)
        out = [bytes(view[pos + i * GID_SIZE:pos + (i + 1) * GID_SIZE]) for i in range(n)]
        pos += n * GID_SIZE
        return out

    gid = bytes(view[4:4 + GID_SIZE])
    pos = 4 + GID_SIZE
    nodes: List[NodeEntities] = []
    for _ in range(count(12)):
        namespace = string()
        name = string()
        nodes.append(NodeEntities(namespace, name, gids(), gids()))
    return gid, nodes


@dataclass(frozen=True)
class EndpointInfo:
    """One endpoint as rclpy's ``get_publishers_info_by_topic`` describes it."""

    node_name: str
    node_namespace: str
    topic_type: str
    endpoint_gid: bytes
    qos: QoSProfile
    type_hash: Optional[str]
    #: the DDS vendor of its participant ("Fast DDS", "Cyclone DDS", "minros", ...)
    vendor: str
    local: bool = False


class Graph:
    """The graph as this participant sees it: fed by discovery events and
    ``ros_discovery_info`` samples, read by the queries. Thread-safe; ``version`` grows with
    every change and :meth:`wait_for_change` waits for it to."""

    def __init__(self, vendor_of: Callable[[bytes], str] = lambda prefix: "") -> None:
        self._lock = threading.Lock()
        self._changed = threading.Condition(self._lock)
        self.version = 0
        self._vendor_of = vendor_of
        #: participant gid -> its nodes (its latest ros_discovery_info sample)
        self._nodes: Dict[bytes, List[NodeEntities]] = {}
        #: endpoint gid -> (its SEDP data, whether it is ours)
        self._endpoints: Dict[bytes, Tuple[EndpointData, bool]] = {}

    # -- feeding -----------------------------------------------------------------------------

    def set_participant_nodes(self, gid: bytes, nodes: List[NodeEntities]) -> None:
        with self._lock:
            self._nodes[gid[:GID_SIZE]] = nodes
            self._bump()

    def remove_participant(self, prefix: bytes) -> None:
        with self._lock:
            self._nodes = {k: v for k, v in self._nodes.items() if k[:12] != prefix}
            self._endpoints = {k: v for k, v in self._endpoints.items() if k[:12] != prefix}
            self._bump()

    def add_endpoint(self, data: EndpointData, local: bool = False) -> None:
        with self._lock:
            self._endpoints[data.guid] = (data, local)
            self._bump()

    def remove_endpoint(self, guid: bytes) -> None:
        with self._lock:
            if self._endpoints.pop(guid, None) is not None:
                self._bump()

    def touch(self) -> None:
        """Something the queries do not show changed (a match): wake the waiters."""
        with self._lock:
            self._bump()

    def _bump(self) -> None:
        self.version += 1
        self._changed.notify_all()

    def wait_for_change(self, version: int, timeout: float) -> int:
        """Wait until the graph's version passes ``version`` (or ``timeout``); the version."""
        deadline = time.monotonic() + timeout
        with self._lock:
            while self.version <= version:
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self._changed.wait(left)
            return self.version

    def wait_until(self, predicate: Callable[[Graph], bool], timeout: float) -> bool:
        """Wait until ``predicate(graph)`` holds (checked after each change)."""
        deadline = time.monotonic() + timeout
        version = -1
        while True:
            if predicate(self):
                return True
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            version = self.wait_for_change(max(version, self.version), left)

    # -- queries -----------------------------------------------------------------------------

    def node_names_and_namespaces(self) -> List[Tuple[str, str]]:
        """Every node of the domain (this participant's too), as rclpy lists them."""
        with self._lock:
            return sorted({(n.name, n.namespace) for nodes in self._nodes.values()
                           for n in nodes})

    def _owner(self, gid: bytes) -> Tuple[str, str]:
        for nodes in self._nodes.values():
            for node in nodes:
                if gid in node.readers or gid in node.writers:
                    return node.name, node.namespace
        return "_NODE_NAME_UNKNOWN_", "_NODE_NAMESPACE_UNKNOWN_"

    def topic_names_and_types(self, include_local: bool = True) -> Dict[str, List[str]]:
        """ROS topics (``/chatter``) and their ROS types (``std_msgs/msg/String``)."""
        return self._names("topic", include_local)

    def service_names_and_types(self, include_local: bool = True) -> Dict[str, List[str]]:
        return self._names("request", include_local)

    def _names(self, kind: str, include_local: bool) -> Dict[str, List[str]]:
        out: Dict[str, Set[str]] = {}
        with self._lock:
            for data, local in self._endpoints.values():
                if local and not include_local:
                    continue
                mapped = names.dds_to_topic(data.topic)
                if mapped is None or mapped[1] != kind:
                    continue
                ros_type = names.dds_to_type(data.type_name) or data.type_name
                out.setdefault(mapped[0], set()).add(ros_type)
        return {k: sorted(v) for k, v in sorted(out.items())}

    def endpoints(self, topic: str, kind: str = "publisher",
                  include_local: bool = True) -> List[EndpointInfo]:
        """The publishers (``kind="publisher"``) or subscriptions of ROS topic ``topic``;
        a service's are its ``request``/``reply`` DDS topics' (``dds_topic=``)."""
        return self.endpoints_of(names.topic_to_dds(topic), kind, include_local)

    def endpoints_of(self, dds_topic: str, kind: str,
                     include_local: bool = True) -> List[EndpointInfo]:
        want_reader = kind in ("subscription", "reader")
        out: List[EndpointInfo] = []
        with self._lock:
            for data, local in self._endpoints.values():
                if data.topic != dds_topic or data.is_reader != want_reader:
                    continue
                if local and not include_local:
                    continue
                name, namespace = self._owner(data.guid)
                out.append(EndpointInfo(
                    name, namespace, names.dds_to_type(data.type_name) or data.type_name,
                    data.guid, from_dds(data.qos), data.user_data_value("typehash"),
                    self._vendor_of(data.guid[:12]), local))
        return out

    def endpoint_data(self, guid: bytes) -> Optional[EndpointData]:
        with self._lock:
            item = self._endpoints.get(guid)
            return item[0] if item is not None else None
