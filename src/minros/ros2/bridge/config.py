"""The explicit bridge configuration: ros1_bridge's ``parameter_bridge`` form, pure.

A YAML document (or the same structure read from the ROS 1 parameter server) with three lists,
as ros1_bridge's README and ``parameter_bridge.cpp`` define them::

    topics:                       # bridged both ways
      - topic: /chatter           # the name on both sides
        type: std_msgs/msg/String # the ROS 2 type (the ROS 1 form std_msgs/String is taken too)
        queue_size: 1             # ROS 1 queue size and, without qos, the ROS 2 depth (default 100)
        qos:                      # optional, every key optional (rclcpp's KeepLast(10) otherwise)
          history: keep_last      # or keep_all (then no depth)
          depth: 10
          reliability: reliable   # or best_effort
          durability: transient_local   # or volatile; transient_local latches the ROS 1 side
          deadline: {secs: 10, nsecs: 2345}
          lifespan: {secs: 20, nsecs: 3456}
          liveliness: liveliness_automatic   # LIVELINESS_{SYSTEM_DEFAULT,AUTOMATIC,
                                             # MANUAL_BY_TOPIC}, either case, or 0..3
          liveliness_lease_duration: {secs: 40, nsecs: 5678}
    services_2_to_1:              # a ROS 1 server, called from ROS 2
      - service: /add_two_ints
        type: roscpp_tutorials/TwoInts   # the ROS 1 type
    services_1_to_2:              # a ROS 2 server, called from ROS 1
      - service: /add_two_ints_2
        type: example_interfaces/srv/AddTwoInts   # the ROS 2 type

ros1_bridge prints what it cannot read and goes on; here every mistake is a
:class:`ConfigError` naming the entry, the key and what is accepted, before anything starts.
The deprecated ``package`` key of services (``type`` without its package) is accepted as
ros1_bridge accepts it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Set

from minros.ros2.rmw.qos import QoSProfile

__all__ = ["Config", "ConfigError", "ServiceConfig", "TopicConfig", "load", "parse", "parse_qos"]

#: parameter_bridge's queue size when an entry gives none (or 0)
DEFAULT_QUEUE_SIZE = 100
#: rclcpp::QoS(rclcpp::KeepLast(10)): parameter_bridge's publisher QoS when ``qos`` is given
QOS_BASE = QoSProfile(depth=10)

_LIVELINESS = {"liveliness_system_default": "automatic", "liveliness_automatic": "automatic",
               "liveliness_manual_by_topic": "manual_by_topic"}
#: rmw_qos_liveliness_policy_t: 0 system default, 1 automatic, 2 manual by node (deprecated,
#: rmw treats it as by topic), 3 manual by topic
_LIVELINESS_CODES = {0: "automatic", 1: "automatic", 2: "manual_by_topic", 3: "manual_by_topic"}


class ConfigError(ValueError):
    """The configuration cannot be used; the text names the entry and what to write."""


@dataclass(frozen=True)
class TopicConfig:
    topic: str
    #: the ROS 2 type, ``pkg/msg/Name``
    type: str
    queue_size: int = DEFAULT_QUEUE_SIZE
    #: the QoS of both ROS 2 endpoints; None: the bridge chooses (see ``qos``)
    qos: Optional[QoSProfile] = None


@dataclass(frozen=True)
class ServiceConfig:
    service: str
    #: ``services_2_to_1``: the ROS 1 type (``pkg/Name``); ``services_1_to_2``: the ROS 2 type
    #: (``pkg/srv/Name``)
    type: str


@dataclass(frozen=True)
class Config:
    topics: List[TopicConfig] = field(default_factory=list)
    #: ROS 2 servers called from ROS 1
    services_1_to_2: List[ServiceConfig] = field(default_factory=list)
    #: ROS 1 servers called from ROS 2
    services_2_to_1: List[ServiceConfig] = field(default_factory=list)

    def __bool__(self) -> bool:
        return bool(self.topics or self.services_1_to_2 or self.services_2_to_1)


def load(path: str) -> Config:
    """The configuration in YAML file ``path``."""
    import yaml

    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as exc:
        raise ConfigError(f"cannot read the bridge configuration {path}: {exc.strerror}") from None
    try:
        document = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path} is not YAML: {str(exc).splitlines()[0]}") from None
    return parse(document, path)


def parse(document: Any, where: str = "the configuration") -> Config:
    """The configuration from its parsed form (a dict of the three lists)."""
    if document is None:
        document = {}
    if not isinstance(document, Mapping):
        raise ConfigError(f"{where}: expected a mapping with the keys topics, services_1_to_2 "
                          f"and services_2_to_1, got {type(document).__name__}")
    unknown = sorted(set(map(str, document)) - {"topics", "services_1_to_2", "services_2_to_1"})
    if unknown:
        raise ConfigError(f"{where}: unknown key {unknown[0]!r} (the keys are topics, "
                          "services_1_to_2 and services_2_to_1)")
    topics = [_topic(entry, f"{where}: topics[{i}]")
              for i, entry in enumerate(_list(document, "topics", where))]
    seen = set()
    for t in topics:
        if t.topic in seen:
            raise ConfigError(f"{where}: topic {t.topic} is listed twice")
        seen.add(t.topic)
    s12 = [_service(e, f"{where}: services_1_to_2[{i}]", ros2=True)
           for i, e in enumerate(_list(document, "services_1_to_2", where))]
    s21 = [_service(e, f"{where}: services_2_to_1[{i}]", ros2=False)
           for i, e in enumerate(_list(document, "services_2_to_1", where))]
    for kind, entries in (("services_1_to_2", s12), ("services_2_to_1", s21)):
        names = [s.service for s in entries]
        for name in names:
            if names.count(name) > 1:
                raise ConfigError(f"{where}: service {name} is listed twice in {kind}")
    both = {s.service for s in s12} & {s.service for s in s21}
    if both:
        raise ConfigError(f"{where}: service {sorted(both)[0]} is in both services_1_to_2 and "
                          "services_2_to_1 (a service has its server on one side)")
    return Config(topics, s12, s21)


def _list(document: Mapping[str, Any], key: str, where: str) -> List[Any]:
    value = document.get(key)
    if value is None:
        return []
    if not isinstance(value, list):
        raise ConfigError(f"{where}: {key} must be a list of entries, got "
                          f"{type(value).__name__}")
    return value


def _name(entry: Mapping[str, Any], key: str, where: str) -> str:
    value = entry.get(key)
    if not isinstance(value, str) or not value.strip():
        raise ConfigError(f"{where}: needs {key}: a name such as /chatter")
    value = value.strip()
    return value if value.startswith("/") else "/" + value


def _entry(entry: Any, where: str, keys: Set[str]) -> Mapping[str, Any]:
    if not isinstance(entry, Mapping):
        raise ConfigError(f"{where}: expected a mapping, got {type(entry).__name__}")
    unknown = sorted(set(map(str, entry)) - keys)
    if unknown:
        raise ConfigError(f"{where}: unknown key {unknown[0]!r} (keys: {', '.join(sorted(keys))})")
    return entry


def _type(value: Any, where: str, kind: str, example: str) -> str:
    if not isinstance(value, str) or value.count("/") not in (1, 2) or "" in value.split("/"):
        raise ConfigError(f"{where}: needs type: a type such as {example}")
    parts = value.strip().split("/")
    if kind == "ros1":
        if len(parts) == 3:  # pkg/srv/Name given for a ROS 1 service: its ROS 1 name
            return f"{parts[0]}/{parts[2]}"
        return value.strip()
    if len(parts) == 2:
        return f"{parts[0]}/{kind}/{parts[1]}"
    if parts[1] != kind:
        raise ConfigError(f"{where}: type {value} is not a {kind} type (such as {example})")
    return value.strip()


def _topic(entry: Any, where: str) -> TopicConfig:
    entry = _entry(entry, where, {"topic", "type", "queue_size", "qos"})
    topic = _name(entry, "topic", where)
    where = f"{where} ({topic})"
    type_name = _type(entry.get("type"), where, "msg", "std_msgs/msg/String")
    queue_size = entry.get("queue_size", 0)
    if queue_size is None:
        queue_size = 0
    if isinstance(queue_size, bool) or not isinstance(queue_size, int) or queue_size < 0:
        raise ConfigError(f"{where}: queue_size must be a whole number (0 or absent: "
                          f"{DEFAULT_QUEUE_SIZE}), got {queue_size!r}")
    queue_size = queue_size or DEFAULT_QUEUE_SIZE
    qos = parse_qos(entry["qos"], f"{where}: qos") if "qos" in entry else None
    return TopicConfig(topic, type_name, queue_size, qos)


def _service(entry: Any, where: str, ros2: bool) -> ServiceConfig:
    entry = _entry(entry, where, {"service", "type", "package"})
    service = _name(entry, "service", where)
    where = f"{where} ({service})"
    type_value = entry.get("type")
    package = entry.get("package")
    if package:  # ros1_bridge's deprecated form: package and type apart
        if not isinstance(package, str) or not isinstance(type_value, str):
            raise ConfigError(f"{where}: package and type must be names")
        type_value = f"{package}/{type_value}"
    if ros2:
        return ServiceConfig(service, _type(type_value, where, "srv", "std_srvs/srv/SetBool"))
    return ServiceConfig(service, _type(type_value, where, "ros1", "std_srvs/SetBool"))


def _duration(value: Any, where: str) -> float:
    if not isinstance(value, Mapping) or set(map(str, value)) - {"secs", "nsecs"}:
        raise ConfigError(f"{where}: expected {{secs: S, nsecs: N}}, got {value!r}")
    secs, nsecs = value.get("secs", 0), value.get("nsecs", 0)
    for part in (secs, nsecs):
        if isinstance(part, bool) or not isinstance(part, int) or part < 0:
            raise ConfigError(f"{where}: secs and nsecs are whole numbers >= 0, got {value!r}")
    total = secs + nsecs / 1e9
    return math.inf if total == 0 else total  # rmw: a zero duration is "not set" (infinite)


def parse_qos(value: Any, where: str) -> QoSProfile:
    """parameter_bridge's ``qos`` mapping as a QoSProfile (KeepLast(10), reliable, volatile
    where a key is absent)."""
    if not isinstance(value, Mapping):
        raise ConfigError(f"{where}: expected a mapping of QoS policies, got "
                          f"{type(value).__name__}")
    keys = {"history", "depth", "reliability", "durability", "deadline", "lifespan",
            "liveliness", "liveliness_lease_duration"}
    unknown = sorted(set(map(str, value)) - keys)
    if unknown:
        raise ConfigError(f"{where}: unknown policy {unknown[0]!r} (policies: "
                          f"{', '.join(sorted(keys))})")
    changes: Dict[str, Any] = {}
    history = value.get("history")
    if history is not None:
        if history == "keep_all":
            changes["history"] = "keep_all"
        elif history == "keep_last":
            depth = value.get("depth")
            if isinstance(depth, bool) or not isinstance(depth, int) or depth < 1:
                raise ConfigError(f"{where}: history keep_last needs depth: a number >= 1")
            changes["history"], changes["depth"] = "keep_last", depth
        else:
            raise ConfigError(f"{where}: history {history!r}: keep_last (with depth) or keep_all")
    elif "depth" in value:
        raise ConfigError(f"{where}: depth without history: write history: keep_last")
    for key, allowed in (("reliability", ("reliable", "best_effort")),
                         ("durability", ("volatile", "transient_local"))):
        if key in value:
            if value[key] not in allowed:
                raise ConfigError(f"{where}: {key} {value[key]!r}: {' or '.join(allowed)}")
            changes[key] = value[key]
    for key in ("deadline", "lifespan", "liveliness_lease_duration"):
        if key in value:
            changes[key] = _duration(value[key], f"{where}: {key}")
    if "liveliness" in value:
        raw = value["liveliness"]
        if isinstance(raw, int) and not isinstance(raw, bool) and raw in _LIVELINESS_CODES:
            changes["liveliness"] = _LIVELINESS_CODES[raw]
        elif isinstance(raw, str) and raw.lower() in _LIVELINESS:
            changes["liveliness"] = _LIVELINESS[raw.lower()]
        else:
            raise ConfigError(f"{where}: liveliness {raw!r}: LIVELINESS_SYSTEM_DEFAULT, "
                              "LIVELINESS_AUTOMATIC or LIVELINESS_MANUAL_BY_TOPIC (either case), "
                              "or 0-3")
    return QOS_BASE.with_(**changes)
