"""ROS 2 nodes on minros's DDS: a :class:`Context` (one DDS participant in a domain, its
``ros_discovery_info`` and graph), :class:`Node` s in it, and their publishers and
subscriptions of serialized CDR bytes.

This layer carries bytes: a publisher is given a sample already serialized (CDR, its 4-byte
encapsulation header first, as rclpy's ``serialize_message`` writes it), a subscription's
callback gets the bytes that arrived. The caller names the ROS type (``std_msgs/msg/String``)
and gives its RIHS01 type hash, which endpoints advertise in USER_DATA as rmw does
(``typehash=RIHS01_...;``).

Threads: a subscription's callback runs in the participant's user-data receive thread; a
service's handler runs in a thread of its own (see ``service``).
"""

from __future__ import annotations

import logging
import os
import threading
from typing import Any, Callable, Dict, List, Optional, Set, Tuple

from minros.ros2.rmw import names
from minros.ros2.rmw.graph import (
    DISCOVERY_TOPIC,
    DISCOVERY_TYPE,
    DISCOVERY_TYPE_HASH,
    EndpointInfo,
    Graph,
    GraphError,
    NodeEntities,
    decode_participant_info,
    encode_participant_info,
)
from minros.ros2.rmw.names import type_hash_user_data
from minros.ros2.rmw.qos import DEFAULT, SERVICES_DEFAULT, QoSProfile
from minros.ros2.rmw.service import Client, Payload, Service
from minros.ros2.rtps import discovery as d
from minros.ros2.rtps import guid as g
from minros.ros2.rtps.discovery import EndpointData
from minros.ros2.rtps.endpoint import Sample
from minros.ros2.rtps.participant import LocalEndpoint, LocalReader, LocalWriter, Participant

__all__ = ["Context", "MessageInfo", "Node", "Publisher", "Subscription", "domain_from_env",
           "type_hash_user_data"]

log = logging.getLogger("minros.ros2")


def domain_from_env(default: int = 0) -> int:
    """ROS_DOMAIN_ID, as rcl reads it (empty or unset: ``default``)."""
    text = os.environ.get("ROS_DOMAIN_ID", "").strip()
    if not text:
        return default
    try:
        value = int(text)
    except ValueError:
        raise ValueError(f"ROS_DOMAIN_ID={text!r}: a number from 0 to 232") from None
    if not 0 <= value <= 232:
        raise ValueError(f"ROS_DOMAIN_ID={value}: a number from 0 to 232")
    return value


class MessageInfo:
    """What arrived with a sample: the publisher's GUID, its sequence number, the source time."""

    __slots__ = ("publisher_gid", "sequence_number", "source_timestamp", "inline_qos",
                 "little", "vendor")

    def __init__(self, sample: Sample, vendor: bytes) -> None:
        self.publisher_gid = sample.writer
        self.sequence_number = sample.sn
        #: nanoseconds since the epoch, as the writer stamped it (None: no INFO_TS)
        self.source_timestamp = sample.timestamp
        self.inline_qos = sample.inline_qos
        self.little = sample.little
        #: the DDS vendor id of the publisher's participant
        self.vendor = vendor


class Context:
    """One ROS 2 context: a DDS participant in ``domain_id`` (ROS_DOMAIN_ID when None) with
    ``ros_discovery_info`` and the graph. Nodes made by :meth:`create_node` share it."""

    def __init__(self, domain_id: Optional[int] = None, *, enclave: str = "/",
                 host: str = "127.0.0.1", **participant: object) -> None:
        self.domain_id = domain_from_env() if domain_id is None else domain_id
        self.enclave = enclave
        self.participant = Participant(self.domain_id, host=host,
                                       user_data=f"enclave={enclave};".encode(),
                                       **participant)  # type: ignore[arg-type]
        self.graph = Graph(self._vendor_of)
        self._lock = threading.Lock()
        self._nodes: List[Node] = []
        self._closed = False
        self.participant.add_listener(self._on_discovery)
        self.participant.start()
        self.gid = self.participant.guid
        info_qos = d.Qos(reliability=d.RELIABLE, durability=d.TRANSIENT_LOCAL,
                         history=d.KEEP_LAST, depth=1)
        self._info_writer = self.participant.create_writer(
            DISCOVERY_TOPIC, DISCOVERY_TYPE, info_qos,
            user_data=type_hash_user_data(DISCOVERY_TYPE_HASH))
        self._info_reader = self.participant.create_reader(
            DISCOVERY_TOPIC, DISCOVERY_TYPE,
            d.Qos(reliability=d.RELIABLE, durability=d.TRANSIENT_LOCAL, history=d.KEEP_ALL,
                  depth=1), self._on_discovery_info,
            user_data=type_hash_user_data(DISCOVERY_TYPE_HASH), ignore_local=True)
        self._publish_info()

    # -- nodes -------------------------------------------------------------------------------

    def create_node(self, name: str, namespace: str = "/") -> Node:
        names.validate_node_name(name)
        node = Node(self, name, names.validate_namespace(namespace))
        with self._lock:
            self._nodes.append(node)
        self._publish_info()
        return node

    def _remove_node(self, node: Node) -> None:
        with self._lock:
            if node in self._nodes:
                self._nodes.remove(node)
        self._publish_info()

    def _publish_info(self) -> None:
        with self._lock:
            if self._closed:
                return
            nodes = [NodeEntities(n.namespace, n.name, list(n._readers), list(n._writers))
                     for n in self._nodes]
        self.graph.set_participant_nodes(self.gid, nodes)
        self._info_writer.write(encode_participant_info(self.gid, nodes))

    def shutdown(self) -> None:
        """Destroy every node and leave the domain (peers are told at once)."""
        with self._lock:
            nodes = list(self._nodes)
        for node in nodes:
            node.destroy()
        with self._lock:
            self._closed = True
        self.participant.close()

    def __enter__(self) -> Context:
        return self

    def __exit__(self, *exc: object) -> None:
        self.shutdown()

    # -- discovery ---------------------------------------------------------------------------

    def _vendor_of(self, prefix: bytes) -> str:
        if prefix == self.participant.prefix:
            return "minros"
        remote = self.participant.remote(prefix)
        return g.vendor_name(remote.vendor if remote is not None else prefix[:2])

    def vendor(self, prefix: bytes) -> bytes:
        """The vendor id of participant ``prefix`` (minros's for this one)."""
        if prefix == self.participant.prefix:
            return g.VENDOR_MINROS
        remote = self.participant.remote(prefix)
        return remote.vendor if remote is not None else b""

    def _on_discovery(self, event: str, obj: object) -> None:
        if event == "endpoint+":
            assert isinstance(obj, EndpointData)
            if obj.topic != DISCOVERY_TOPIC:
                self.graph.add_endpoint(obj)
        elif event == "endpoint-":
            assert isinstance(obj, EndpointData)
            self.graph.remove_endpoint(obj.guid)
        elif event == "participant-":
            self.graph.remove_participant(obj.prefix)  # type: ignore[attr-defined]
        elif event in ("matched", "unmatched", "incompatible", "participant+"):
            self.graph.touch()

    def _on_discovery_info(self, sample: Sample) -> None:
        try:
            gid, nodes = decode_participant_info(bytes(sample.payload))
        except GraphError as exc:
            log.warning("ROS 2: ignored a ros_discovery_info sample from %s: %s",
                        g.guid_text(sample.writer[:12]), exc)
            return
        if gid[:12] != sample.writer[:12]:
            return  # a participant speaks only for itself
        self.graph.set_participant_nodes(gid, nodes)

    # -- graph queries (rclpy's names) -------------------------------------------------------

    def get_node_names_and_namespaces(self) -> List[Tuple[str, str]]:
        return self.graph.node_names_and_namespaces()

    def get_topic_names_and_types(self) -> List[Tuple[str, List[str]]]:
        return list(self.graph.topic_names_and_types().items())

    def get_service_names_and_types(self) -> List[Tuple[str, List[str]]]:
        return list(self.graph.service_names_and_types().items())

    def get_publishers_info_by_topic(self, topic: str) -> List[EndpointInfo]:
        return self.graph.endpoints(names.resolve(topic), "publisher")

    def get_subscriptions_info_by_topic(self, topic: str) -> List[EndpointInfo]:
        return self.graph.endpoints(names.resolve(topic), "subscription")


class Node:
    """A ROS 2 node: a name and namespace in a Context, and its endpoints."""

    def __init__(self, context: Context, name: str, namespace: str) -> None:
        self.context = context
        self.name = name
        self.namespace = namespace
        self._readers: List[bytes] = []
        self._writers: List[bytes] = []
        self._entities: List[object] = []
        self._destroyed = False

    @property
    def fully_qualified_name(self) -> str:
        return self.namespace.rstrip("/") + "/" + self.name

    def resolve(self, name: str) -> str:
        return names.resolve(name, self.namespace, self.name)

    # -- endpoints ---------------------------------------------------------------------------

    def create_publisher(self, topic: str, type_name: str, qos: QoSProfile = DEFAULT, *,
                         type_hash: Optional[str] = None, **tuning: Any) -> Publisher:
        """A publisher of serialized ``type_name`` (``std_msgs/msg/String``) samples."""
        return Publisher(self, self.resolve(topic), type_name, qos, type_hash, tuning)

    def create_subscription(self, topic: str, type_name: str,
                            callback: Callable[[Payload, MessageInfo], None],
                            qos: QoSProfile = DEFAULT, *, type_hash: Optional[str] = None,
                            check: Optional[Callable[[Payload], object]] = None
                            ) -> Subscription:
        """A subscription: ``callback(payload, info)`` for each sample, in order. ``check``
        (optional) is tried on each payload first; a sample it raises on is dropped with one
        log line per publisher."""
        return Subscription(self, self.resolve(topic), type_name, callback, qos, type_hash,
                            check)

    def create_service(self, name: str, srv_type: str,
                       handler: Callable[[bytes], Optional[Payload]],
                       qos: QoSProfile = SERVICES_DEFAULT, *, request_hash: Optional[str] = None,
                       response_hash: Optional[str] = None) -> Service:
        """A service server of ``srv_type`` (``std_srvs/srv/SetBool``): ``handler(request)``
        returns the serialized response (see ``service``)."""
        return Service(self, self.resolve(name), srv_type, handler, qos, request_hash,
                       response_hash)

    def create_client(self, name: str, srv_type: str, qos: QoSProfile = SERVICES_DEFAULT, *,
                      request_hash: Optional[str] = None,
                      response_hash: Optional[str] = None) -> Client:
        """A service client of ``srv_type``."""
        return Client(self, self.resolve(name), srv_type, qos, request_hash, response_hash)

    def _register(self, entity: object, readers: List[bytes], writers: List[bytes]) -> None:
        if self._destroyed:
            raise RuntimeError(f"node {self.fully_qualified_name} is destroyed")
        self._entities.append(entity)
        self._readers += readers
        self._writers += writers
        self.context._publish_info()

    def _unregister(self, entity: object, readers: List[bytes], writers: List[bytes]) -> None:
        if entity in self._entities:
            self._entities.remove(entity)
        self._readers = [r for r in self._readers if r not in readers]
        self._writers = [w for w in self._writers if w not in writers]
        if not self._destroyed:
            self.context._publish_info()

    def destroy(self) -> None:
        """Destroy every endpoint of the node and remove it from the graph."""
        if self._destroyed:
            return
        self._destroyed = True
        for entity in list(self._entities):
            entity.destroy()  # type: ignore[attr-defined]
        self.context._remove_node(self)

    # -- graph (rclpy's names) ---------------------------------------------------------------

    def get_node_names_and_namespaces(self) -> List[Tuple[str, str]]:
        return self.context.get_node_names_and_namespaces()

    def get_topic_names_and_types(self) -> List[Tuple[str, List[str]]]:
        return self.context.get_topic_names_and_types()

    def get_publishers_info_by_topic(self, topic: str) -> List[EndpointInfo]:
        return self.context.graph.endpoints(self.resolve(topic), "publisher")

    def get_subscriptions_info_by_topic(self, topic: str) -> List[EndpointInfo]:
        return self.context.graph.endpoints(self.resolve(topic), "subscription")


def _endpoint_graph_entry(context: Context, endpoint: LocalEndpoint) -> None:
    context.graph.add_endpoint(endpoint.data, local=True)


class Publisher:
    """Publishes serialized samples on one topic."""

    def __init__(self, node: Node, topic: str, type_name: str, qos: QoSProfile,
                 type_hash: Optional[str], tuning: Dict[str, Any]) -> None:
        self.node = node
        self.topic = topic
        self.type_name = type_name
        self.qos = qos
        self.type_hash = type_hash
        part = node.context.participant
        self.writer: LocalWriter = part.create_writer(
            names.topic_to_dds(topic,
                               avoid_ros_namespace_conventions=qos.avoid_ros_namespace_conventions),
            names.type_to_dds(type_name), qos.to_dds(), user_data=type_hash_user_data(type_hash),
            **tuning)
        self.gid = self.writer.guid
        _endpoint_graph_entry(node.context, self.writer)
        node._register(self, [], [self.gid])

    def publish(self, payload: Payload) -> int:
        """Send one serialized sample (CDR, encapsulation header first); its sequence number.
        The payload object is kept, not copied, while it is in the history (resends, late
        joiners): do not change it afterwards (bytes cannot be)."""
        return self.writer.write(payload)

    def get_subscription_count(self) -> int:
        """Matched subscriptions (rclpy's name)."""
        return self.writer.matched_count()

    def wait_for_subscriptions(self, count: int = 1, timeout: float = 5.0) -> bool:
        """Wait until ``count`` subscriptions matched."""
        w = self.writer
        with w.lock:
            return w.changed.wait_for(lambda: len(w.matched) >= count or w.closed, timeout) \
                and len(w.matched) >= count

    def wait_for_acknowledgments(self, timeout: float = 5.0) -> bool:
        """Wait until every reliable subscription has every sample (rclpy's
        ``wait_for_all_acked``)."""
        return self.writer.wait_acknowledged(self.writer.machine.last_sn, timeout)

    def destroy(self) -> None:
        self.node.context.participant.delete(self.writer)
        self.node.context.graph.remove_endpoint(self.gid)
        self.node._unregister(self, [], [self.gid])


class Subscription:
    """Receives serialized samples of one topic."""

    def __init__(self, node: Node, topic: str, type_name: str,
                 callback: Callable[[Payload, MessageInfo], None], qos: QoSProfile,
                 type_hash: Optional[str], check: Optional[Callable[[Payload], object]]) -> None:
        self.node = node
        self.topic = topic
        self.type_name = type_name
        self.qos = qos
        self.callback = callback
        self.check = check
        self.rejected = 0
        self._reported: Set[bytes] = set()
        part = node.context.participant
        self.reader: LocalReader = part.create_reader(
            names.topic_to_dds(topic,
                               avoid_ros_namespace_conventions=qos.avoid_ros_namespace_conventions),
            names.type_to_dds(type_name), qos.to_dds(), self._on_sample,
            user_data=type_hash_user_data(type_hash))
        self.gid = self.reader.guid
        _endpoint_graph_entry(node.context, self.reader)
        node._register(self, [self.gid], [])

    def _on_sample(self, sample: Sample) -> None:
        payload = sample.payload
        reason = _encapsulation_problem(payload)
        if reason is None and self.check is not None:
            try:
                self.check(payload)
            except Exception as exc:  # the caller's decoder: any failure is the sample's
                reason = f"{type(exc).__name__}: {exc}"
        if reason is not None:
            self.rejected += 1
            publisher = sample.writer
            if publisher not in self._reported:
                self._reported.add(publisher)
                log.warning("ROS 2 topic %s: dropped a sample from %s that does not decode as "
                            "%s (%s)", self.topic, g.guid_text(publisher), self.type_name,
                            reason)
            return
        self.callback(payload, MessageInfo(sample, self.node.context.vendor(sample.writer[:12])))

    def get_publisher_count(self) -> int:
        return self.reader.matched_count()

    def wait_for_publishers(self, count: int = 1, timeout: float = 5.0) -> bool:
        r = self.reader
        with r.lock:
            return r.changed.wait_for(lambda: len(r.matched) >= count or r.closed, timeout) \
                and len(r.matched) >= count

    def destroy(self) -> None:
        self.node.context.participant.delete(self.reader)
        self.node.context.graph.remove_endpoint(self.gid)
        self.node._unregister(self, [self.gid], [])


def _encapsulation_problem(payload: Payload) -> Optional[str]:
    """Why a user sample is not plain CDR (rmw's only encoding), or None."""
    if len(payload) < 4:
        return f"{len(payload)} bytes: shorter than the CDR encapsulation header"
    kind = payload[0] << 8 | payload[1]
    if kind not in (0x0000, 0x0001):
        return f"encapsulation 0x{kind:04x}, not plain CDR (0x0000/0x0001)"
    return None
