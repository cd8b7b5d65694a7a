"""Which topics and services to bridge, pure: the two graphs and the options in, a plan out.

The rules are ros1_bridge's ``dynamic_bridge`` (``src/dynamic_bridge.cpp``, ``update_bridge``):

* a topic is bridged **ROS 1 -> ROS 2** when a ROS 1 node publishes it and a ROS 2 node
  subscribes to it (``--bridge-all-1to2-topics``: whenever a ROS 1 node publishes it); the
  ROS 2 type is the subscriber's, which the ROS 1 type must map to;
* **ROS 2 -> ROS 1** when a ROS 2 node publishes it and a ROS 1 node subscribes to it
  (``--bridge-all-2to1-topics``: whenever a ROS 2 node publishes it); the ROS 1 type is the
  subscriber's, or the one the ROS 2 type maps to;
* every ROS 1 service is offered in ROS 2, and every ROS 2 service (a server, not a client) in
  ROS 1, when its type maps; a name served on both sides is bridged neither way (calls would
  reach two servers);
* the bridge's own endpoints are not in the graphs it is given (the caller leaves them out:
  its own ROS 1 node by name, its own ROS 2 endpoints by being local), so nothing it bridges
  is bridged back;
* a topic with ROS 2 endpoints of two types is not bridged, as in ros1_bridge.

With an explicit configuration (``config``, parameter_bridge's), exactly what it lists is
bridged: each topic both ways, each service in the direction of its list, whatever the graphs.

Left out of the dynamic bridge (``IGNORED_*``): what every node has and no user means to
bridge: ROS 1's ``/rosout``, ``/rosout_agg`` and the logger services of each node
(``roscpp/GetLoggers``, ``roscpp/SetLoggerLevel``); ROS 2's ``/rosout``, ``/parameter_events``
and each node's parameter and type-description services. ros1_bridge leaves these out because
they have no type mapping; minros could make one, so it leaves them out by name.

A type that cannot be bridged is a *problem*: one line, keyed so that the caller says it once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, Iterable, Mapping, Optional, Protocol, Tuple

from minros.ros2.bridge.config import Config
from minros.ros2.bridge.qos import subscription_qos
from minros.ros2.rmw.qos import QoSProfile

__all__ = ["IGNORED_ROS1_SERVICE_TYPES", "IGNORED_ROS1_TOPICS", "IGNORED_ROS2_SERVICE_PACKAGES",
           "IGNORED_ROS2_TOPICS", "Options", "Plan", "Ros1Graph", "Ros2Graph", "Ros2Topic",
           "ServiceBridge", "TopicBridge", "TypeLookup", "Unknown", "Unmapped", "plan"]

IGNORED_ROS1_TOPICS = frozenset({"/rosout", "/rosout_agg"})
IGNORED_ROS2_TOPICS = frozenset({"/rosout", "/parameter_events"})
IGNORED_ROS1_SERVICE_TYPES = frozenset({"roscpp/GetLoggers", "roscpp/SetLoggerLevel"})
#: each rclpy/rclcpp node's parameter services and (Jazzy on) its type description service
IGNORED_ROS2_SERVICE_PACKAGES = frozenset({"rcl_interfaces", "type_description_interfaces"})
#: each ROS 1 node's logger services, known by name before their type is asked
IGNORED_ROS1_SERVICE_SUFFIXES = ("/get_loggers", "/set_logger_level")

ONE_TO_TWO = "1to2"
TWO_TO_ONE = "2to1"


class Unmapped(LookupError):
    """A type has no counterpart on the other side; ``reason`` says why."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


class Unknown(LookupError):
    """A ROS 1 type whose definition the bridge does not have (not installed here): its
    publisher's connection header will bring it."""


class TypeLookup(Protocol):
    """What the plan asks of the type mapping (the runtime's is the Mapper's)."""

    def ros2_for_ros1(self, ros1_type: str) -> str:
        """The ROS 2 message type of a ROS 1 one; Unmapped or Unknown."""

    def ros1_for_ros2(self, ros2_type: str) -> str:
        """The ROS 1 message type of a ROS 2 one (made when none exists); Unmapped."""

    def ros2_service_for_ros1(self, ros1_type: str) -> str:
        """The ROS 2 service type of a ROS 1 one; Unmapped or Unknown."""

    def ros1_service_for_ros2(self, ros2_type: str) -> str:
        """The ROS 1 service type of a ROS 2 one; Unmapped."""


@dataclass(frozen=True)
class Ros1Graph:
    """Other nodes' topics and services on the ROS 1 master."""

    #: topic -> its ROS 1 type
    publishers: Mapping[str, str] = field(default_factory=dict)
    #: topic -> its ROS 1 type ("" when the master knows none)
    subscribers: Mapping[str, str] = field(default_factory=dict)
    #: service -> its ROS 1 type (as its server answers a probe)
    services: Mapping[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Ros2Topic:
    """The remote publishers or subscriptions of one ROS 2 topic."""

    types: Tuple[str, ...]
    qos: Tuple[QoSProfile, ...] = ()


@dataclass(frozen=True)
class Ros2Graph:
    """Other participants' topics and service servers in the ROS 2 domain."""

    publishers: Mapping[str, Ros2Topic] = field(default_factory=dict)
    subscribers: Mapping[str, Ros2Topic] = field(default_factory=dict)
    #: service -> the ROS 2 types of its servers
    services: Mapping[str, Tuple[str, ...]] = field(default_factory=dict)


@dataclass(frozen=True)
class Options:
    bridge_all_1to2: bool = False
    bridge_all_2to1: bool = False
    #: ROS 1 queue sizes and ROS 2 depths of the dynamic bridges (ros1_bridge's: 10)
    queue_size: int = 10
    #: parameter_bridge's configuration: when given, exactly what it lists is bridged
    config: Optional[Config] = None


@dataclass(frozen=True)
class TopicBridge:
    """One topic carried one way."""

    topic: str
    direction: str
    ros1_type: str
    #: None: decided by the first message's connection header (a ROS 1 type not installed
    #: here, published with its definition)
    ros2_type: Optional[str]
    queue_size: int
    #: the ROS 2 endpoint's QoS: the subscription's (2to1); for 1to2 only an explicit one
    #: (else chosen from the ROS 1 publisher's latching when it connects)
    qos: Optional[QoSProfile] = None
    explicit: bool = False


@dataclass(frozen=True)
class ServiceBridge:
    """One service offered on the other side: ``2to1`` a ROS 1 server called from ROS 2,
    ``1to2`` a ROS 2 server called from ROS 1 (ros1_bridge's names: requests' direction)."""

    service: str
    direction: str
    ros1_type: str
    ros2_type: str


@dataclass
class Plan:
    topics: Dict[Tuple[str, str], TopicBridge] = field(default_factory=dict)
    services: Dict[str, ServiceBridge] = field(default_factory=dict)
    #: a key per fault (so it is said once) -> the line that says it
    problems: Dict[str, str] = field(default_factory=dict)


def _single(topic: str, types: Iterable[str], side: str, out: Plan) -> Optional[str]:
    kinds = sorted(set(types))
    if len(kinds) == 1:
        return kinds[0]
    if kinds:
        out.problems[f"types {side} {topic} {kinds}"] = (
            f"{topic} is not bridged: its {side} endpoints have several types "
            f"({', '.join(kinds)})")
    return None


def plan(ros1: Ros1Graph, ros2: Ros2Graph, options: Options, types: TypeLookup) -> Plan:
    """What to bridge now."""
    out = Plan()
    if options.config:
        _explicit(options.config, ros2, types, out)
        return out
    _topics_1to2(ros1, ros2, options, types, out)
    _topics_2to1(ros1, ros2, options, types, out)
    _services(ros1, ros2, types, out)
    return out


def _topics_1to2(ros1: Ros1Graph, ros2: Ros2Graph, options: Options, types: TypeLookup,
                 out: Plan) -> None:
    for topic, ros1_type in sorted(ros1.publishers.items()):
        if topic in IGNORED_ROS1_TOPICS or topic in IGNORED_ROS2_TOPICS:
            continue
        subscribers = ros2.subscribers.get(topic)
        wanted: Optional[str] = None
        if subscribers is not None and subscribers.types:
            wanted = _single(topic, subscribers.types, "ROS 2 subscription", out)
            if wanted is None:
                continue
        elif not options.bridge_all_1to2:
            continue
        try:
            ros2_type: Optional[str] = types.ros2_for_ros1(ros1_type)
        except Unknown:
            ros2_type = wanted  # the publisher's header tells; checked against ``wanted`` then
        except Unmapped as exc:
            out.problems[f"1to2 {topic} {ros1_type}"] = (
                f"{topic} is not bridged to ROS 2: {ros1_type} {exc.reason}")
            continue
        if wanted is not None and ros2_type != wanted:
            out.problems[f"1to2 {topic} {ros1_type} {wanted}"] = (
                f"{topic} is not bridged to ROS 2: ROS 1 publishes {ros1_type}, which maps to "
                f"{ros2_type}, and ROS 2 subscribes to {wanted}")
            continue
        out.topics[(topic, ONE_TO_TWO)] = TopicBridge(topic, ONE_TO_TWO, ros1_type, ros2_type,
                                                      options.queue_size)


def _topics_2to1(ros1: Ros1Graph, ros2: Ros2Graph, options: Options, types: TypeLookup,
                 out: Plan) -> None:
    for topic, publishers in sorted(ros2.publishers.items()):
        if topic in IGNORED_ROS2_TOPICS or topic in IGNORED_ROS1_TOPICS:
            continue
        ros2_type = _single(topic, publishers.types, "ROS 2 publisher", out)
        if ros2_type is None:
            continue
        subscribed = ros1.subscribers.get(topic)
        if subscribed is None and not options.bridge_all_2to1:
            continue
        try:
            ros1_type = types.ros1_for_ros2(ros2_type)
        except Unmapped as exc:
            out.problems[f"2to1 {topic} {ros2_type}"] = (
                f"{topic} is not bridged to ROS 1: {ros2_type} {exc.reason}")
            continue
        if subscribed and subscribed != "*" and subscribed != ros1_type:
            try:
                theirs: Optional[str] = types.ros2_for_ros1(subscribed)
            except (Unmapped, Unknown):
                theirs = None
            if theirs != ros2_type:
                out.problems[f"2to1 {topic} {ros2_type} {subscribed}"] = (
                    f"{topic} is not bridged to ROS 1: ROS 2 publishes {ros2_type}, which "
                    f"maps to {ros1_type}, and ROS 1 subscribes to {subscribed}")
                continue
            ros1_type = subscribed
        qos = subscription_qos(publishers.qos, options.queue_size)
        out.topics[(topic, TWO_TO_ONE)] = TopicBridge(topic, TWO_TO_ONE, ros1_type, ros2_type,
                                                      options.queue_size, qos)


def _services(ros1: Ros1Graph, ros2: Ros2Graph, types: TypeLookup, out: Plan) -> None:
    both = set(ros1.services) & set(ros2.services)
    for name in sorted(both):
        out.problems[f"service both {name}"] = (
            f"service {name} is not bridged: it has servers in ROS 1 and in ROS 2 (a call "
            "would reach two servers)")
    for name, ros1_type in sorted(ros1.services.items()):
        if name in both or ros1_type in IGNORED_ROS1_SERVICE_TYPES \
                or name.endswith(IGNORED_ROS1_SERVICE_SUFFIXES):
            continue
        try:
            ros2_type = types.ros2_service_for_ros1(ros1_type)
        except (Unmapped, Unknown) as exc:
            out.problems[f"service 2to1 {name} {ros1_type}"] = (
                f"service {name} is not bridged to ROS 2: {ros1_type} "
                f"{getattr(exc, 'reason', 'is not installed here')}")
            continue
        out.services[name] = ServiceBridge(name, TWO_TO_ONE, ros1_type, ros2_type)
    for name, server_types in sorted(ros2.services.items()):
        if name in both:
            continue
        if any(t.split("/")[0] in IGNORED_ROS2_SERVICE_PACKAGES for t in server_types):
            continue
        service_type = _single(name, server_types, "ROS 2 service", out)
        if service_type is None:
            continue
        try:
            ros1_type = types.ros1_service_for_ros2(service_type)
        except Unmapped as exc:
            out.problems[f"service 1to2 {name} {service_type}"] = (
                f"service {name} is not bridged to ROS 1: {service_type} {exc.reason}")
            continue
        out.services[name] = ServiceBridge(name, ONE_TO_TWO, ros1_type, service_type)


def _explicit(config: Config, ros2: Ros2Graph, types: TypeLookup, out: Plan) -> None:
    for entry in config.topics:
        try:
            ros1_type = types.ros1_for_ros2(entry.type)
        except Unmapped as exc:
            out.problems[f"config topic {entry.topic}"] = (
                f"{entry.topic} is not bridged: {entry.type} {exc.reason}")
            continue
        out.topics[(entry.topic, ONE_TO_TWO)] = TopicBridge(
            entry.topic, ONE_TO_TWO, ros1_type, entry.type, entry.queue_size, entry.qos, True)
        publishers = ros2.publishers.get(entry.topic)
        offered = publishers.qos if publishers is not None else ()
        qos = subscription_qos(offered, entry.queue_size, entry.qos)
        out.topics[(entry.topic, TWO_TO_ONE)] = TopicBridge(
            entry.topic, TWO_TO_ONE, ros1_type, entry.type, entry.queue_size, qos, True)
    for service in config.services_2_to_1:
        try:
            ros2_type = types.ros2_service_for_ros1(service.type)
        except (Unmapped, Unknown) as exc:
            out.problems[f"config service {service.service}"] = (
                f"service {service.service} is not bridged to ROS 2: {service.type} "
                f"{getattr(exc, 'reason', 'is not installed here')}")
            continue
        out.services[service.service] = ServiceBridge(service.service, TWO_TO_ONE,
                                                      service.type, ros2_type)
    for service in config.services_1_to_2:
        try:
            ros1_type = types.ros1_service_for_ros2(service.type)
        except Unmapped as exc:
            out.problems[f"config service {service.service}"] = (
                f"service {service.service} is not bridged to ROS 1: {service.type} "
                f"{exc.reason}")
            continue
        out.services[service.service] = ServiceBridge(service.service, ONE_TO_TWO, ros1_type,
                                                      service.type)
