"""The running bridge: one ROS 1 node on the master, one ROS 2 node in the domain, the bridges.

Threads (besides those of minros's ROS 1 node and of the DDS participant):

- ``minros-ros2-ros1graph`` reads the master every ``poll_interval`` (0.2 s): other nodes'
  publishers, subscribers and services; each new service's type is asked once (a TCPROS probe,
  as ros1_bridge and rosservice do) in a small pool.
- ``minros-ros2-control`` owns every bridge: woken by a new ROS 1 reading or a change of the
  ROS 2 graph (discovery), it computes the :mod:`plan` and makes and removes bridges.

Messages are converted in the thread that receives them, with no hand-off: a ROS 1
subscriber's receive thread converts (``Transcoder.ros1_to_cdr``) and writes to DDS; the
participant's receive thread converts ROS 2 samples and publishes them on TCPROS. Neither side
builds message objects: both ends carry serialized bytes (:mod:`raw` on the ROS 1 side, CDR on
the ROS 2 side), and the generated converters of :mod:`minros.ros2.types` copy each array once.

No loops: the graphs the plan reads leave out the bridge's own endpoints (its ROS 1 node by
name, its ROS 2 endpoints as local ones), and what the bridge publishes on one side and hears
back on the same side (its own ROS 1 subscriber connects to its own ROS 1 publisher of a
topic bridged both ways; its ROS 2 subscription to its own writer) is recognised by the
connection header's ``callerid`` and the sample's publisher GID and dropped.

ROS 1 types nobody installed: a ROS 1 -> ROS 2 subscriber asks with md5sum ``*``; the
publisher's connection header brings type, md5sum and ``message_definition``, from which the
mapper makes the ROS 2 type (and its hash) before the first message is written. A latched
ROS 1 publisher (``latching=1``) turns the bridge's ROS 2 publisher transient local before its
first (latched) message is written.

Faults are one log line each (:class:`OnceLog`): a type that does not map, a message or
sample that does not convert (per topic and publisher), a service that fails; the bridge goes
on. The DDS layer's own lines (a QoS that cannot match, a peer gone after its lease) go to the
same log.
"""

from __future__ import annotations

import logging
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from typing import Any, Callable, Dict, List, Optional, Set, Tuple

import minros
from minros.exceptions import ServiceException
from minros.msgs.registry import REGISTRY, UnknownTypeError
from minros.msgs.spec import MsgSpecError
from minros.ros2.bridge import plan as planning
from minros.ros2.bridge.config import Config
from minros.ros2.bridge.plan import (
    ONE_TO_TWO,
    TWO_TO_ONE,
    Options,
    Plan,
    Ros1Graph,
    Ros2Graph,
    Ros2Topic,
    ServiceBridge,
    TopicBridge,
    Unknown,
    Unmapped,
)
from minros.ros2.bridge.qos import latches, publisher_qos
from minros.ros2.bridge.raw import raw_class, raw_service_class
from minros.ros2.rmw import Context, Node, Publisher, ServiceTimeout
from minros.ros2.rmw import names as ros2_names
from minros.ros2.rmw.qos import QoSProfile, from_dds
from minros.ros2.types import Mapper, MessageMapping, NoMappingError, ServiceMapping
from minros.tools.master import Master
from minros.tools.services import probe_service

__all__ = ["Bridge", "BridgeOptions", "OnceLog", "TypeBook"]

#: how often the control thread looks without news (retries, periodic checks)
TICK = 0.05
#: a bridge that could not be made is tried again after this long
RETRY = 2.0
#: how long a service's type probe may take
PROBE_TIMEOUT = 2.0
#: problems said once each, up to this many keys (then one line says more are not shown)
MAX_SAID = 10_000
#: idle persistent ROS 1 service connections kept per bridged ROS 1 service
IDLE_PROXIES = 4


@dataclass(frozen=True)
class BridgeOptions:
    distro: str = "jazzy"
    name: str = "ros_bridge"
    bridge_all_1to2: bool = False
    bridge_all_2to1: bool = False
    queue_size: int = 10
    config: Optional[Config] = None
    #: how long a call from ROS 1 waits for a ROS 2 service (ros1_bridge's
    #: service_execution_timeout: 5 s)
    service_timeout: float = 5.0
    poll_interval: float = 0.2

    def plan_options(self) -> Options:
        return Options(self.bridge_all_1to2, self.bridge_all_2to1, self.queue_size, self.config)


class OnceLog:
    """Say each fault once (by key): a peer or a graph cannot flood the log."""

    def __init__(self, say: Callable[[str], None]) -> None:
        self.say = say
        self._said: Set[str] = set()
        self._full = False
        self._lock = threading.Lock()

    def __call__(self, key: str, text: Optional[str] = None) -> bool:
        with self._lock:
            if key in self._said:
                return False
            if len(self._said) >= MAX_SAID:
                if self._full:
                    return False
                self._full = True
                text = f"more than {MAX_SAID} distinct problems: the rest are not shown"
            else:
                self._said.add(key)
        self.say(text if text is not None else key)
        return True

    def forget(self, key: str) -> None:
        with self._lock:
            self._said.discard(key)


# -- types ---------------------------------------------------------------------------------------


class TypeBook:
    """The bridge's type mapping (a :class:`~minros.ros2.types.Mapper` of one distro) as the
    plan asks for it, and the ROS 1 facts (md5sum, definition) the ROS 1 side needs.
    ``generation`` grows when a connection header teaches it a type (the plan is redone)."""

    def __init__(self, distro: str) -> None:
        self.mapper = Mapper(distro)
        self.lock = threading.RLock()
        self.generation = 0

    # -- what the plan asks --
    def ros2_for_ros1(self, ros1_type: str) -> str:
        return self.message(ros1_type).ros2_type

    def ros1_for_ros2(self, ros2_type: str) -> str:
        with self.lock:
            try:
                return self.mapper.message_from_ros2(ros2_type).ros1_type
            except UnknownTypeError:
                raise Unmapped("is not known here: ROS 2's discovery carries a type's name and "
                               "hash, not its definition, and minros bundles no such type "
                               "(a ROS 1 publisher of it teaches it to the bridge)") from None
            except NoMappingError as exc:
                raise Unmapped(exc.reason) from None
            except (MsgSpecError, ValueError) as exc:
                raise Unmapped(f"cannot be made a ROS 1 type: {exc}") from None

    def ros2_service_for_ros1(self, ros1_type: str) -> str:
        return self.service(ros1_type).ros2_type

    def ros1_service_for_ros2(self, ros2_type: str) -> str:
        parts = ros2_type.split("/")
        if len(parts) != 3 or parts[1] != "srv":
            raise Unmapped("is not a service type")
        package, _, short = parts
        packages = [package]
        if package.endswith("_interfaces"):
            packages.append(package[:-len("_interfaces")] + "_msgs")
        with self.lock:
            for candidate in (f"{p}/{short}" for p in packages):
                try:
                    if self.mapper.service(candidate).ros2_type == ros2_type:
                        return candidate
                except (UnknownTypeError, NoMappingError, MsgSpecError):
                    continue
        raise Unmapped("has no ROS 1 counterpart here (no installed ROS 1 service of that "
                       "package and name maps to it)")

    # -- mappings --
    def message(self, ros1_type: str) -> MessageMapping:
        """Unknown (not installed) or Unmapped."""
        with self.lock:
            try:
                return self.mapper.message(ros1_type)
            except UnknownTypeError:
                raise Unknown(ros1_type) from None
            except NoMappingError as exc:
                raise Unmapped(exc.reason) from None
            except MsgSpecError as exc:
                raise Unmapped(f"has a definition that does not parse: {exc}") from None

    def service(self, ros1_type: str) -> ServiceMapping:
        with self.lock:
            try:
                return self.mapper.service(ros1_type)
            except UnknownTypeError:
                raise Unknown(ros1_type) from None
            except NoMappingError as exc:
                raise Unmapped(exc.reason) from None
            except MsgSpecError as exc:
                raise Unmapped(f"has a definition that does not parse: {exc}") from None

    def learn(self, ros1_type: str, md5sum: str, definition: str) -> MessageMapping:
        """The mapping of what a publisher's connection header says it sends: the installed
        type when its md5sum is that one, else a type made from the header's definition."""
        with self.lock:
            try:
                if self.ros1_md5(ros1_type) == md5sum:
                    return self.message(ros1_type)
            except Unknown:
                pass
            if not definition:
                raise Unmapped(f"(md5sum {md5sum}) is not installed here and its publisher sent "
                               "no message_definition")
            try:
                self.mapper.add_ros1_definition(ros1_type, definition)
            except MsgSpecError as exc:
                raise Unmapped(f"has a message_definition that does not parse: {exc}") from None
            self.generation += 1
            mine = self.ros1_md5(ros1_type)
            if mine != md5sum:
                raise Unmapped(f"has md5sum {md5sum}, but its message_definition gives {mine}")
            return self.message(ros1_type)

    def ros1_md5(self, ros1_type: str) -> str:
        with self.lock:
            try:
                return self.mapper.ros1_context.md5sum(ros1_type)
            except UnknownTypeError:
                raise Unknown(ros1_type) from None

    def ros1_full_text(self, ros1_type: str) -> str:
        with self.lock:
            return self.mapper.ros1_context.full_text(ros1_type)

    def ros1_srv_md5(self, ros1_type: str) -> str:
        # services map from installed ROS 1 definitions only (the mapper's)
        with self.lock:
            return REGISTRY.srv_md5sum(ros1_type)


# -- the ROS 1 graph --------------------------------------------------------------------------


class Ros1Watcher:
    """Reads the master as node ``me`` (whose own endpoints are left out); a service's type is
    probed once per (service, providers)."""

    def __init__(self, me: str, report: OnceLog) -> None:
        self.me = me
        self.master = Master(me, timeout=PROBE_TIMEOUT)
        self.report = report
        #: service -> (its providers, its type or None while unknown, when to ask again)
        self._services: Dict[str, Tuple[Tuple[str, ...], Optional[str], float]] = {}
        self._pool = ThreadPoolExecutor(max_workers=4, thread_name_prefix="minros-ros2-probe")
        self._lock = threading.Lock()
        self.changed: Callable[[], None] = lambda: None

    def close(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)
        self.master.close()

    def read(self) -> Ros1Graph:
        """The graph now; MasterIOError (an OSError) when the master does not answer."""
        pubs, subs, srvs = self.master.system_state()
        types = dict(self.master.topic_types())
        me = self.me
        publishers = {t: types.get(t, "") for t, nodes in pubs
                      if any(n != me for n in nodes) and types.get(t, "") not in ("", "*")}
        subscribers = {t: types.get(t, "") for t, nodes in subs if any(n != me for n in nodes)}
        services: Dict[str, str] = {}
        now = time.monotonic()
        wanted = {}
        for name, nodes in srvs:
            others = tuple(sorted(n for n in nodes if n != me))
            if not others or name.endswith(planning.IGNORED_ROS1_SERVICE_SUFFIXES):
                continue
            wanted[name] = others
        with self._lock:
            for name in [s for s in self._services if s not in wanted]:
                del self._services[name]
            for name, others in wanted.items():
                known = self._services.get(name)
                if known is not None and known[0] == others:
                    if known[1] is not None:
                        services[name] = known[1]
                    elif known[2] <= now:
                        self._services[name] = (others, None, now + 3600)  # asking
                        self._pool.submit(self._probe, name, others, 1.0)
                    continue
                self._services[name] = (others, None, now + 3600)
                self._pool.submit(self._probe, name, others, 0.5)
        return Ros1Graph(publishers, subscribers, services)

    def _probe(self, name: str, providers: Tuple[str, ...], backoff: float) -> None:
        try:
            uri = self.master.lookup_service(name)
            header = probe_service(uri, name, self.me, PROBE_TIMEOUT)
            if "error" in header:
                raise OSError(header["error"])
            found: Optional[str] = header.get("type") or None
            if found is None:
                raise OSError("its probe answer names no type")
        except Exception as exc:  # noqa: BLE001 - any failure: ask again later
            with self._lock:
                if name in self._services and self._services[name][0] == providers:
                    self._services[name] = (providers, None,
                                            time.monotonic() + min(backoff * 2, 10.0))
            if backoff >= 4.0:
                self.report(f"probe {name}", f"cannot ask service {name} for its type: {exc}")
            return
        with self._lock:
            if name in self._services and self._services[name][0] == providers:
                self._services[name] = (providers, found, 0.0)
        self.changed()


# -- topic bridges ------------------------------------------------------------------------------


class Ros1ToRos2:
    """A ROS 1 topic published in ROS 2: a raw ROS 1 subscriber (md5sum ``*``), a ROS 2
    publisher of the mapped type."""

    def __init__(self, bridge: Bridge, spec: TopicBridge) -> None:
        self.bridge = bridge
        self.spec = spec
        self.topic = spec.topic
        self.lock = threading.Lock()
        self.publisher: Optional[Publisher] = None
        self.mapping: Optional[MessageMapping] = None
        self.latched = False
        #: md5sum a publisher sends -> its converter (None: not bridged, said once)
        self.converters: Dict[str, Optional[Any]] = {}
        if spec.ros2_type is not None:
            try:
                mapping = bridge.types.message(spec.ros1_type)
            except (Unknown, Unmapped):
                mapping = None  # decided by the publisher's connection header
            if mapping is not None and mapping.ros2_type == spec.ros2_type:
                self.converters[bridge.types.ros1_md5(spec.ros1_type)] = mapping.transcoder
                self._advertise(mapping, False)
        # no queue limit: what TCPROS carried is not dropped here (a receive reads what one
        # buffer holds, and the conversion and the DDS write never wait)
        self.subscriber = minros.Subscriber(spec.topic, raw_class(spec.ros1_type),
                                            self._on_message, tcp_nodelay=True)

    @property
    def ros2_type(self) -> Optional[str]:
        return self.mapping.ros2_type if self.mapping is not None else self.spec.ros2_type

    def _advertise(self, mapping: MessageMapping, latched: bool) -> None:
        qos = publisher_qos(self.topic, latched, self.spec.queue_size, self.spec.qos)
        old = self.publisher
        publisher = self.bridge.node.create_publisher(self.topic, mapping.ros2_type, qos,
                                                      type_hash=mapping.type_hash)
        # big samples' bursts leave from the ROS 1 receive thread, on time (see the writer)
        publisher.writer.pace_in_caller = True
        self.bridge.own_writers.add(publisher.gid)
        self.mapping = mapping
        self.publisher = publisher
        if old is not None:
            old.destroy()
            self.bridge.own_writers.discard(old.gid)
        if latched:
            self.bridge.info(f"{self.topic} is latched in ROS 1: its ROS 2 publisher is "
                             f"transient local ({qos.describe()})")

    def _converter(self, header: Dict[str, str]) -> Optional[Any]:
        md5 = header.get("md5sum", "")
        type_name = header.get("type", self.spec.ros1_type)
        with self.lock:
            if md5 in self.converters:
                return self.converters[md5]
            converter = None
            try:
                mapping = self.bridge.types.learn(type_name, md5,
                                                  header.get("message_definition", ""))
                wanted = self.ros2_type
                if wanted is not None and mapping.ros2_type != wanted:
                    raise Unmapped(f"maps to {mapping.ros2_type}, and the topic is bridged as "
                                   f"{wanted}")
                if self.publisher is None:
                    self._advertise(mapping, header.get("latching") == "1")
                    self.latched = header.get("latching") == "1"
                converter = mapping.transcoder
                self.bridge.wake()
            except Unmapped as exc:
                self.bridge.once(f"1to2 header {self.topic} {type_name} {md5}",
                                 f"{self.topic} from {header.get('callerid', '?')} is not "
                                 f"bridged to ROS 2: {type_name} {exc.reason}")
            self.converters[md5] = converter
            return converter

    def _on_message(self, msg: Any) -> None:
        header = msg._connection_header
        if header.get("callerid") == self.bridge.me:
            return  # the bridge's own ROS 1 publisher of this topic: that came from ROS 2
        converter = self.converters.get(header.get("md5sum", ""), False)
        if converter is False:
            converter = self._converter(header)
        if converter is None:
            return
        if header.get("latching") == "1" and not self.latched and self.spec.qos is None:
            with self.lock:
                if not self.latched and self.mapping is not None:
                    self.latched = True
                    self._advertise(self.mapping, True)
        try:
            data = converter.ros1_to_cdr(msg._buff)
        except Exception as exc:  # noqa: BLE001 - the publisher's bytes: say so, go on
            caller = header.get("callerid", "?")
            self.bridge.once(f"bad 1to2 {self.topic} {caller}",
                             f"dropping messages on {self.topic} from {caller} that do not "
                             f"convert to {self.ros2_type} ({exc}); said once")
            return
        publisher = self.publisher
        if publisher is not None:
            publisher.publish(data)

    def close(self) -> None:
        self.subscriber.unregister()
        with self.lock:
            if self.publisher is not None:
                self.publisher.destroy()
                self.bridge.own_writers.discard(self.publisher.gid)
                self.publisher = None

    def keeps(self, spec: TopicBridge) -> bool:
        """Whether this bridge already is ``spec`` (the ROS 2 type learnt since counts)."""
        if spec == self.spec:
            return True
        learnt = replace(self.spec, ros2_type=self.ros2_type)
        return learnt == replace(spec, ros2_type=spec.ros2_type or self.ros2_type)


class Ros2ToRos1:
    """A ROS 2 topic published in ROS 1: a ROS 2 subscription, a raw ROS 1 publisher of the
    mapped type (md5sum and definition from the mapping) that counts Header's seq."""

    def __init__(self, bridge: Bridge, spec: TopicBridge) -> None:
        assert spec.ros2_type is not None and spec.qos is not None
        self.bridge = bridge
        self.spec = spec
        self.topic = spec.topic
        types = bridge.types
        mapping = types.message(spec.ros1_type)
        if mapping.ros2_type != spec.ros2_type:
            raise Unmapped(f"{spec.ros1_type} maps to {mapping.ros2_type}, not {spec.ros2_type}")
        self.transcoder = mapping.transcoder
        self.cls = raw_class(spec.ros1_type, types.ros1_md5(spec.ros1_type),
                             types.ros1_full_text(spec.ros1_type))
        self.seq = 0
        self.publisher = minros.Publisher(spec.topic, self.cls, latch=latches(spec.qos),
                                          queue_size=spec.queue_size, tcp_nodelay=True)
        try:
            self.subscription = bridge.node.create_subscription(
                spec.topic, spec.ros2_type, self._on_sample, spec.qos,
                type_hash=mapping.type_hash)
        except BaseException:
            self.publisher.unregister()
            raise

    def _on_sample(self, payload: Any, info: Any) -> None:
        if info.publisher_gid in self.bridge.own_writers:
            return  # the bridge's own ROS 2 publisher of this topic: that came from ROS 1
        try:
            data = self.transcoder.cdr_to_ros1(payload, seq=self.seq + 1)
        except Exception as exc:  # noqa: BLE001 - the peer's bytes: say so, go on
            gid = info.publisher_gid.hex()
            self.bridge.once(f"bad 2to1 {self.topic} {gid}",
                             f"dropping samples on {self.topic} from ROS 2 publisher {gid} that "
                             f"do not decode as {self.spec.ros2_type} ({exc}); said once")
            return
        self.seq += 1
        try:
            self.publisher.publish(self.cls(data))
        except minros.ROSException:
            pass  # unregistered meanwhile: the bridge is being removed

    def close(self) -> None:
        self.subscription.destroy()
        self.publisher.unregister()

    def keeps(self, spec: TopicBridge) -> bool:
        return spec == self.spec


# -- service bridges ------------------------------------------------------------------------------


class Ros1ServiceInRos2:
    """A ROS 1 server offered to ROS 2 clients (ros1_bridge's 2 to 1): a ROS 2 service whose
    handler calls the ROS 1 service through persistent connections."""

    def __init__(self, bridge: Bridge, spec: ServiceBridge) -> None:
        self.bridge = bridge
        self.spec = spec
        self.name = spec.service
        mapping = bridge.types.service(spec.ros1_type)
        self.request = mapping.request.transcoder
        self.response = mapping.response.transcoder
        self.service_class = raw_service_class(spec.ros1_type,
                                               bridge.types.ros1_srv_md5(spec.ros1_type))
        self._idle: List[Any] = []
        self._lock = threading.Lock()
        self.server = bridge.node.create_service(
            spec.service, spec.ros2_type, self._handle,
            request_hash=mapping.request.type_hash, response_hash=mapping.response.type_hash)

    def _handle(self, request: bytes) -> Optional[bytes]:
        try:
            ros1_request = self.request.cdr_to_ros1(request, seq=0)
        except Exception as exc:  # noqa: BLE001
            self.bridge.once(f"bad request {self.name}",
                             f"service {self.name}: a ROS 2 request that does not decode as "
                             f"{self.spec.ros2_type} ({exc}); not answered")
            return None
        with self._lock:
            proxy = self._idle.pop() if self._idle else None
        if proxy is None:
            proxy = minros.ServiceProxy(self.name, self.service_class, persistent=True)
        try:
            reply = proxy.call(self.service_class._request_class(  # type: ignore[attr-defined]
                ros1_request))
            data: bytes = self.response.ros1_to_cdr(reply._buff)
        except Exception as exc:  # noqa: BLE001 - the ROS 1 side failed: no ROS 2 reply
            proxy.close()
            self.bridge.once(f"call {self.name} {exc}",
                             f"service {self.name}: the ROS 1 call failed ({exc}); the ROS 2 "
                             "client gets no reply")
            return None
        with self._lock:
            if len(self._idle) < IDLE_PROXIES:
                self._idle.append(proxy)
                proxy = None
        if proxy is not None:
            proxy.close()
        return data

    def close(self) -> None:
        self.server.destroy()
        with self._lock:
            idle, self._idle = self._idle, []
        for proxy in idle:
            proxy.close()


class Ros2ServiceInRos1:
    """A ROS 2 server offered to ROS 1 clients (ros1_bridge's 1 to 2): a ROS 1 service whose
    handler calls the ROS 2 service."""

    def __init__(self, bridge: Bridge, spec: ServiceBridge) -> None:
        self.bridge = bridge
        self.spec = spec
        self.name = spec.service
        mapping = bridge.types.service(spec.ros1_type)
        self.request = mapping.request.transcoder
        self.response = mapping.response.transcoder
        self.service_class = raw_service_class(spec.ros1_type,
                                               bridge.types.ros1_srv_md5(spec.ros1_type))
        # (rmw puts the request's hash on the request topic, the response's on the reply's)
        self.client = bridge.node.create_client(
            spec.service, spec.ros2_type, request_hash=mapping.request.type_hash,
            response_hash=mapping.response.type_hash)
        try:
            self.service = minros.Service(spec.service, self.service_class, self._handle)
        except BaseException:
            self.client.destroy()
            raise

    def _handle(self, request: Any) -> Any:
        timeout = self.bridge.options.service_timeout
        try:
            data = self.request.ros1_to_cdr(request._buff)
        except Exception as exc:  # noqa: BLE001
            raise ServiceException(f"the request does not convert to {self.spec.ros2_type}: "
                                   f"{exc}") from None
        if not self.client.service_is_ready() and not self.client.wait_for_service(timeout):
            raise ServiceException(f"the ROS 2 service {self.name} is not available")
        try:
            reply = self.client.call(data, timeout)
        except ServiceTimeout:
            raise ServiceException(f"no reply from the ROS 2 service {self.name} within "
                                   f"{timeout:g} s") from None
        try:
            return self.service_class._response_class(  # type: ignore[attr-defined]
                self.response.cdr_to_ros1(reply, seq=0))
        except Exception as exc:  # noqa: BLE001
            raise ServiceException(f"the ROS 2 reply does not decode as "
                                   f"{self.spec.ros2_type}: {exc}") from None

    def close(self) -> None:
        self.service.shutdown()
        self.client.destroy()


# -- the bridge ---------------------------------------------------------------------------------


class Bridge:
    """Bridges the master of ROS_MASTER_URI (through this process's ROS 1 node, made by
    ``minros.init_node``) with ``context``'s ROS 2 domain through ``node``."""

    def __init__(self, options: BridgeOptions, context: Context, node: Node,
                 say: Callable[[str], None] = minros.logwarn,
                 info: Callable[[str], None] = minros.loginfo) -> None:
        self.options = options
        self.context = context
        self.node = node
        self.say = say
        self.info = info
        self.once = OnceLog(say)
        self.me = minros.get_name()
        self.types = TypeBook(options.distro)
        #: GIDs of the bridge's own ROS 2 writers (their samples heard back are dropped)
        self.own_writers: Set[bytes] = set()
        self.topics: Dict[Tuple[str, str], Any] = {}
        self.services: Dict[str, Any] = {}
        self._retry: Dict[Tuple[str, str], float] = {}
        self.watcher = Ros1Watcher(self.me, self.once)
        self.watcher.changed = self.wake
        self.ros1: Optional[Ros1Graph] = None
        self._ros1_version = 0
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._master_down = False
        self._threads: List[threading.Thread] = []
        self.rounds = 0

    def start(self) -> None:
        for target, name in ((self._ros1_loop, "minros-ros2-ros1graph"),
                             (self._control_loop, "minros-ros2-control")):
            thread = threading.Thread(target=target, name=name, daemon=True)
            thread.start()
            self._threads.append(thread)

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        for thread in self._threads:
            thread.join(5)
        for bridge in list(self.topics.values()) + list(self.services.values()):
            try:
                bridge.close()
            except Exception:  # noqa: BLE001, S110 - shutting down: the rest still closes
                pass
        self.topics.clear()
        self.services.clear()
        self.watcher.close()

    def wake(self) -> None:
        self._wake.set()

    # -- the ROS 1 graph thread --
    def _ros1_loop(self) -> None:
        while not self._stop.is_set():
            try:
                graph = self.watcher.read()
            except OSError as exc:
                if not self._master_down:
                    self._master_down = True
                    self.say(f"the ROS master does not answer ({exc}); the bridges stay as they "
                             "are until it does")
            except Exception as exc:  # noqa: BLE001 - a bug must not stop the bridge
                self.once(f"ros1 graph {exc!r}", f"reading the ROS 1 graph failed: {exc!r}")
            else:
                if self._master_down:
                    self._master_down = False
                    self.info("the ROS master answers again")
                if graph != self.ros1:
                    self.ros1 = graph
                    self._wake.set()
            self._stop.wait(self.options.poll_interval)

    # -- the control thread --
    def _control_loop(self) -> None:
        graph = self.context.graph
        seen: Tuple[int, int, Optional[Ros1Graph]] = (-1, -1, None)
        version = graph.version
        while not self._stop.is_set():
            version = graph.wait_for_change(version, TICK)
            if self._wake.is_set():
                self._wake.clear()
            if self._stop.is_set():
                break
            state = (version, self.types.generation, self.ros1)
            due = any(at <= time.monotonic() for at in self._retry.values())
            if state == seen and not due:
                continue
            seen = state
            try:
                self.step()
            except Exception as exc:  # noqa: BLE001
                self.once(f"control {exc!r}", f"bridging failed: {exc!r}")

    def ros2_graph(self) -> Ros2Graph:
        """Other participants' endpoints, in one pass over what discovery knows."""
        pubs: Dict[str, List[Tuple[str, QoSProfile]]] = {}
        subs: Dict[str, List[Tuple[str, QoSProfile]]] = {}
        servers: Dict[str, Set[str]] = {}
        for data in self.context.participant.remote_endpoints():
            mapped = ros2_names.dds_to_topic(data.topic)
            ros_type = ros2_names.dds_to_type(data.type_name)
            if mapped is None or ros_type is None:
                continue
            name, kind = mapped
            if kind == "topic":
                (subs if data.is_reader else pubs).setdefault(name, []).append(
                    (ros_type, from_dds(data.qos)))
            elif kind == "request" and data.is_reader:
                servers.setdefault(name, set()).add(ros_type)

        def table(found: Dict[str, List[Tuple[str, QoSProfile]]]) -> Dict[str, Ros2Topic]:
            return {k: Ros2Topic(tuple(sorted({t for t, _ in v})), tuple(q for _, q in v))
                    for k, v in found.items()}

        return Ros2Graph(table(pubs), table(subs),
                         {k: tuple(sorted(v)) for k, v in servers.items()})

    def step(self) -> Plan:
        """One round: plan from both graphs, then make and remove bridges."""
        self.rounds += 1
        ros1 = self.ros1 if self.ros1 is not None else Ros1Graph()
        wanted = planning.plan(ros1, self.ros2_graph(), self.options.plan_options(), self.types)
        for problem, text in wanted.problems.items():
            self.once(problem, text)
        now = time.monotonic()
        for key in [k for k in self.topics if k not in wanted.topics
                    or not self.topics[k].keeps(wanted.topics[k])]:
            bridge = self.topics.pop(key)
            self._close(bridge, f"{key[0]} {_DIRECTION[key[1]]}")
        for key, spec in wanted.topics.items():
            if key in self.topics or self._retry.get(("topic " + key[1], key[0]), 0) > now:
                continue
            make = Ros1ToRos2 if spec.direction == ONE_TO_TWO else Ros2ToRos1
            made = self._make(("topic " + key[1], key[0]), make, spec,
                              f"{spec.topic} {_DIRECTION[spec.direction]} "
                              f"({_types_text(spec)})")
            if made is not None:
                self.topics[key] = made
        for service in [n for n in self.services if n not in wanted.services
                        or self.services[n].spec != wanted.services[n]]:
            self._close(self.services.pop(service), f"service {service}")
        for service, sspec in wanted.services.items():
            if service in self.services or self._retry.get(("service", service), 0) > now:
                continue
            smake = Ros1ServiceInRos2 if sspec.direction == TWO_TO_ONE else Ros2ServiceInRos1
            made = self._make(("service", service), smake, sspec,
                              f"service {service} {_SERVICE_DIRECTION[sspec.direction]} "
                              f"({sspec.ros1_type} <-> {sspec.ros2_type})")
            if made is not None:
                self.services[service] = made
        kept = {("topic " + d, t) for t, d in wanted.topics} | {("service", n)
                                                                for n in wanted.services}
        for stale in [k for k in self._retry if k not in kept]:
            del self._retry[stale]
        return wanted

    def _make(self, key: Tuple[str, str], make: Any, spec: Any, what: str) -> Any:
        try:
            made = make(self, spec)
        except Unmapped as exc:
            self._retry[key] = time.monotonic() + RETRY
            self.once(f"make {key} {exc.reason}", f"cannot bridge {what}: {exc.reason}")
            return None
        except Exception as exc:  # noqa: BLE001 - tried again after RETRY
            self._retry[key] = time.monotonic() + RETRY
            self.once(f"make {key} {exc!r}", f"cannot bridge {what}: {exc}")
            return None
        self._retry.pop(key, None)
        self.info(f"bridging {what}")
        return made

    def _close(self, bridge: Any, what: str) -> None:
        try:
            bridge.close()
        except Exception as exc:  # noqa: BLE001
            self.once(f"close {what} {exc!r}", f"closing the bridge of {what}: {exc}")
        self.info(f"stopped bridging {what}")

    def status(self) -> Dict[str, List[str]]:
        """What is bridged now, by kind (for tests and the command's report)."""
        return {"1to2": sorted(t for t, d in self.topics if d == ONE_TO_TWO),
                "2to1": sorted(t for t, d in self.topics if d == TWO_TO_ONE),
                "services": sorted(self.services)}


_DIRECTION = {ONE_TO_TWO: "ROS 1 -> ROS 2", TWO_TO_ONE: "ROS 2 -> ROS 1"}
_SERVICE_DIRECTION = {TWO_TO_ONE: "of ROS 1 to ROS 2 clients", ONE_TO_TWO: "of ROS 2 to ROS 1 clients"}


def _types_text(spec: TopicBridge) -> str:
    return f"{spec.ros1_type} <-> {spec.ros2_type or 'the type its publisher sends'}"


# -- the program ----------------------------------------------------------------------------------


class _ToRos1Log(logging.Handler):
    """The DDS layer's warnings (``minros.ros2``: QoS that cannot match, peers gone, samples
    that do not decode) into the ROS 1 node's log, console and /rosout."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = record.getMessage()
            if record.levelno >= logging.WARNING:
                minros.logwarn(text)
            else:
                minros.loginfo(text)
        except Exception:  # noqa: BLE001, S110 - logging must not raise into the DDS threads
            pass


def run(options: BridgeOptions, context: Context, node: Node,
        config_from_parameters: bool = False, argv: Optional[List[str]] = None,
        announce: Callable[[str], None] = print) -> int:
    """Join the master with ``context``'s ROS 2 domain (its ``node`` made first, so ROS 2's
    graph lists it at once) and bridge until Ctrl-C or a ROS shutdown; the exit status. The
    context is shut down on return."""
    import signal
    import sys

    from minros.ros2.bridge import config as configuration
    from minros.signals import SignalWatch
    from minros.tools.master import get_master_uri

    def fail(text: str) -> int:
        print(f"minros ros2: error: {text}", file=sys.stderr)
        return 1

    dds_log = logging.getLogger("minros.ros2")
    handler = _ToRos1Log()
    try:
        dds_log.addHandler(handler)
        dds_log.propagate = False
        minros.init_node(options.name, argv=argv, disable_signals=True)
        stop = threading.Event()
        SignalWatch(lambda _signum: stop.set(), "ros2-signals").install(
            (signal.SIGINT, signal.SIGTERM))
        minros.on_shutdown(stop.set)
        if config_from_parameters:
            document = {key: minros.get_param(key) for key in
                        ("topics", "services_1_to_2", "services_2_to_1") if minros.has_param(key)}
            try:
                config = configuration.parse(document, "the parameters topics, "
                                                       "services_1_to_2, services_2_to_1")
            except configuration.ConfigError as exc:
                minros.signal_shutdown("bad configuration")
                return fail(str(exc))
            options = replace(options, config=config)
        bridge = Bridge(options, context, node)
        bridge.start()
        flags = [text for text, on in (("all ROS 1 topics to ROS 2", options.bridge_all_1to2),
                                        ("all ROS 2 topics to ROS 1", options.bridge_all_2to1))
                 if on]
        mode = ("exactly the configured topics and services" if options.config else
                ", ".join(["as dynamic_bridge", *flags]))
        announce(f"minros ros2: bridging the ROS master at {get_master_uri()} as "
                 f"{minros.get_name()} and ROS 2 domain {context.domain_id} ({options.distro}) "
                 f"as /{node.name}: {mode}")
        try:
            while not stop.wait(0.5):
                if minros.is_shutdown():
                    break
        finally:
            bridge.stop()
            minros.signal_shutdown("minros ros2 stopped")
    finally:
        context.shutdown()
        dds_log.removeHandler(handler)
        dds_log.propagate = True
    return 0
