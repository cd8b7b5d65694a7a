"""The running bridge: one ROS node on the local master, one Zenoh session, three threads.

- ``minros-zenoh-graph`` reads the local master every ``poll_interval`` (0.1 s, as
  zenoh-bridge-ros1) into a ``graph.Snapshot``; probes of new publishers and services run in
  a small pool.
- ``minros-zenoh-control`` owns every bridge object: it expires silent remote resources,
  computes the ``plan`` from the snapshot and the remote table, creates and removes bridges,
  and sends the beacons of the local resources (once when declared, then every second).
- Zenoh's own threads deliver beacons (into the remote table, waking the control thread),
  samples (``Inlet``: checked, then published in ROS in that thread, no hand-off) and queries
  (``Queryable``: handed to a pool of 8, as a service call may take long; past 64 waiting,
  refused). Callbacks are declared ``indirect=False`` (zenoh-python would otherwise start a
  thread per subscriber and queryable, a thread per remote topic), but for the samples of the
  topics local nodes subscribe to (``Inlet``'s ``threaded``: the local graph bounds those).

What remote beacons can make is bounded (a peer on a ``--listen`` port can send any): the
remote table holds at most ``MAX_REMOTE`` resources; at most ``max_remote`` bridges exist for
remote beacons alone (``plan.limit_remote``: the first heard are kept, so earlier peers keep
theirs); they are made at ``create_rate`` a second at most, after what the local graph asks
for, and one round spends at most ``CREATE_BUDGET`` seconds making bridges; each bound, when
hit, is one log line, then one a minute. The threads are a constant: graph, control, the
probe and call pools, Zenoh's own.

ROS side, only the public API: a ``Subscriber`` with a raw class per topic carried out (the
receive thread puts each message on Zenoh: no hand-off either), a ``Publisher`` with the
remote type, md5sum and definition per topic carried in, a ``ServiceProxy`` per service
answered on Zenoh and a ``Service`` per remote service. What the bridge publishes itself also
reaches its own subscriber of that topic (a node's subscribers connect to its publishers):
those messages are recognised by the connection header's ``callerid`` and dropped.
"""

from __future__ import annotations

import json
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Tuple

import zenoh

import minros
from minros.exceptions import ServiceException
from minros.tools.master import get_master_uri
from minros.zenoh import keys, layout, meta
from minros.zenoh.discovery import (
    BoundLog,
    Chatter,
    Declarations,
    OnceLog,
    RemoteTable,
    TableFull,
    TokenBucket,
)
from minros.zenoh.graph import LocalGraph, PublisherInfo, Snapshot
from minros.zenoh.keys import KeyMappingError
from minros.zenoh.plan import Plan, Topic, limit_remote, plan, remote_only
from minros.zenoh.raw import raw_class, raw_service_class

__all__ = ["Bridge", "BridgeError", "Options", "zenoh_config"]

#: how often the control thread wakes without news (expiry, beacons)
TICK = 0.05
#: a ROS publisher fed from Zenoh keeps at most this many messages for a slow subscriber
QUEUE_SIZE = 100
#: a bridge that failed to be made is tried again after this long
RETRY = 2.0
#: how long a query for a topic's record may take (a minros bridge answers in milliseconds;
#: zenoh-bridge-ros1 has no queryable, so the query ends at once)
META_TIMEOUT = 1.0
#: idle persistent service connections kept per answered service
IDLE_PROXIES = 4
#: service calls from Zenoh waiting for the pool before new ones are refused
MAX_PENDING_CALLS = 64
#: seconds one control round may spend making bridges (the rest wait for the next round)
CREATE_BUDGET = 0.25
#: bridges that exist for remote beacons alone, and how fast they are made
MAX_REMOTE_BRIDGES = 1000
CREATE_RATE = 50.0
CREATE_BURST = 100.0


def _direct(fn: Callable[[Any], None]) -> Any:
    """A Zenoh callback run in Zenoh's own thread (zenoh-python's default runs each
    subscriber's and queryable's callback in a thread of its own: one per remote topic)."""
    return zenoh.handlers.Callback(fn, indirect=False)


class BridgeError(Exception):
    """The bridge cannot start; the text says why and what to change."""


@dataclass
class Options:
    mode: str = "peer"
    listen: List[str] = field(default_factory=list)
    connect: List[str] = field(default_factory=list)
    multicast_scouting: bool = True
    namespace: str = keys.DEFAULT_NAMESPACE
    service_timeout: float = 10.0
    poll_interval: float = 0.1
    #: data samples skip Zenoh's batching (latency over throughput of tiny messages)
    express: bool = True
    #: bridges that exist for remote beacons alone (see the module doc), and their rate
    max_remote: int = MAX_REMOTE_BRIDGES
    create_rate: float = CREATE_RATE


def zenoh_config(options: Options) -> Any:
    """The Zenoh configuration of ``options``."""
    if options.mode not in ("peer", "client"):
        raise BridgeError(f"--mode must be peer or client, not {options.mode}")
    config = zenoh.Config()
    config.insert_json5("mode", json.dumps(options.mode))
    if options.listen:
        config.insert_json5("listen/endpoints", json.dumps(list(options.listen)))
    if options.connect:
        config.insert_json5("connect/endpoints", json.dumps(list(options.connect)))
        # a restarted peer is found again within about a second, not after a growing back-off
        config.insert_json5("connect/retry", json.dumps(
            {"period_init_ms": 250, "period_max_ms": 1000, "period_increase_factor": 2}))
    config.insert_json5("scouting/multicast/enabled", json.dumps(options.multicast_scouting))
    return config


# -- the four kinds of bridge -------------------------------------------------------------------


class Outlet:
    """A topic carried from ROS to Zenoh: a local subscriber, a Zenoh publisher, and the
    queryable answering minros bridges with the definition and the latched message."""

    def __init__(self, bridge: Bridge, topic: Topic, info: Optional[PublisherInfo]) -> None:
        name, type_name, md5 = topic
        self.bridge = bridge
        self.me = minros.get_name()
        self.key = keys.data_key(name, type_name, md5, bridge.options.namespace)
        self.meta_key = keys.meta_key(name, type_name, md5, bridge.options.namespace)
        self.type, self.md5sum = type_name, md5
        self.definition = info.definition if info else bridge.graph.installed_definition(type_name, md5)
        self.latching = bool(info and info.latching)
        self.latched: Optional[bytes] = None
        session = bridge.session
        self.publisher = session.declare_publisher(
            self.key, congestion_control=zenoh.CongestionControl.BLOCK,
            reliability=zenoh.Reliability.RELIABLE, express=bridge.options.express,
            allowed_destination=zenoh.Locality.REMOTE)
        self.queryable = session.declare_queryable(self.meta_key, _direct(self._on_meta),
                                                   allowed_origin=zenoh.Locality.REMOTE)
        self.subscriber = minros.Subscriber(name, raw_class(type_name, md5, self.definition),
                                            self._on_message, tcp_nodelay=True)

    def _on_message(self, msg: Any) -> None:
        header = msg._connection_header
        if header.get("callerid") == self.me:
            return  # the bridge's own publisher of this topic: that came from Zenoh
        data = msg._buff
        if data.__class__ is not bytes and data.__class__ is not bytearray:
            data = bytes(data)
        self.publisher.put(data)
        if header.get("latching") == "1":
            self.latching = True
            self.latched = bytes(data)

    def _on_meta(self, query: Any) -> None:
        record = meta.TopicMeta(self.type, self.md5sum, self.definition, self.latching,
                                self.latched if self.latching else None)
        try:
            query.reply(self.meta_key, meta.encode(record))
        except Exception as exc:  # noqa: BLE001 - the querier left: nothing to tell
            self.bridge.once(f"meta reply {exc}", f"cannot answer a query on {self.meta_key}: {exc}")

    def close(self) -> None:
        self.subscriber.unregister()
        self.queryable.undeclare()
        self.publisher.undeclare()


class Inlet:
    """A topic carried from Zenoh to ROS: a Zenoh subscriber and a local publisher with the
    remote type, md5sum and (when a minros bridge told it) definition and latching.

    The Zenoh subscriber comes first and keeps the last sample that arrives before the
    publisher exists, then the publishing bridge is asked for its record: a latched message
    sent while this inlet was being made is not lost either way.

    ``threaded``: the samples are taken by a thread of the subscriber's own (zenoh-python's
    default), which costs a thread but about 60 us less CPU per sample than a callback in
    Zenoh's thread, which has to take the GIL each time; an inlet a local node subscribes to
    is threaded (the local graph bounds those), one made for remote beacons alone is not
    until a local node subscribes (:meth:`thread`)."""

    def __init__(self, bridge: Bridge, topic: Topic, threaded: bool = False) -> None:
        name, type_name, md5 = topic
        self.bridge = bridge
        self.topic = topic
        self.key = keys.data_key(name, type_name, md5, bridge.options.namespace)
        self.publisher: Any = None
        self._early: Optional[Tuple[bytes, str]] = None
        self._lock = threading.Lock()
        self.threaded = threaded
        self.subscriber = self._declare(threaded)
        try:
            self.record = record = bridge.ask_meta(topic)
            definition = (record.definition if record and record.definition
                          else bridge.graph.installed_definition(type_name, md5))
            self.definition = definition
            self.latching = bool(record and record.latching)
            self.cls = raw_class(type_name, md5, definition)
            self.check = bridge.checker(type_name, md5, definition, name)
            publisher = minros.Publisher(name, self.cls, latch=self.latching,
                                         queue_size=QUEUE_SIZE, tcp_nodelay=True)
        except BaseException:
            self.subscriber.undeclare()
            raise
        if record is not None and record.latching and record.latched is not None:
            self._send(publisher, record.latched)
        with self._lock:
            self.publisher = publisher
            early, self._early = self._early, None
        if early is not None:
            self._publish(*early)

    def _declare(self, threaded: bool) -> Any:
        handler = self._on_sample if threaded else _direct(self._on_sample)
        return self.bridge.session.declare_subscriber(self.key, handler,
                                                      allowed_origin=zenoh.Locality.REMOTE)

    def thread(self) -> None:
        """Take the samples in a thread from now on (a local node subscribes now). The
        direct subscriber goes first: a sample in between is lost, none is delivered twice."""
        if self.threaded:
            return
        self.threaded = True
        old = self.subscriber
        old.undeclare()
        self.subscriber = self._declare(True)

    def _on_sample(self, sample: Any) -> None:
        data = sample.payload.to_bytes()
        if self.publisher is None:
            with self._lock:
                if self.publisher is None:
                    self._early = (data, sample)
                    return
        self._publish(data, sample)

    def _publish(self, data: bytes, sample: Any = None) -> None:
        check = self.check
        if check is not None:
            try:
                check(data)
            except layout.Malformed as exc:
                key = str(sample.key_expr) if sample is not None else self.key
                self.bridge.once(f"malformed {key}", f"dropping samples on {key} that are not "
                                 f"one {self.topic[1]} ({exc}); this is said once")
                return
        self._send(self.publisher, data)

    def _send(self, publisher: Any, data: bytes) -> None:
        try:
            publisher.publish(self.cls(data))
        except minros.ROSException:  # unregistered meanwhile (the bridge is removing it)
            pass

    def close(self) -> None:
        self.subscriber.undeclare()
        self.publisher.unregister()


class Queryable:
    """A local service answered on Zenoh: each query calls it through a ServiceProxy."""

    def __init__(self, bridge: Bridge, topic: Topic) -> None:
        name, type_name, md5 = topic
        self.bridge = bridge
        self.name = name
        self.key = keys.data_key(name, type_name, md5, bridge.options.namespace)
        self.service_class = raw_service_class(type_name, md5)
        self.check = bridge.service_checker(type_name, md5, "Request")
        self._idle: List[Any] = []
        self._lock = threading.Lock()
        self.queryable = bridge.session.declare_queryable(
            self.key, _direct(self._on_query), allowed_origin=zenoh.Locality.REMOTE)

    def _on_query(self, query: Any) -> None:
        if not self.bridge.submit_call(self._answer, query):
            query.reply_err(f"the bridge has {MAX_PENDING_CALLS} calls waiting: {self.name} "
                            "is not called, try again")

    def _answer(self, query: Any) -> None:
        payload = query.payload
        data = payload.to_bytes() if payload is not None else b""
        if self.check is not None:
            try:
                self.check(data)
            except layout.Malformed as exc:
                self.bridge.once(f"malformed {self.key}", f"refusing queries on {self.key} "
                                 f"that are not one request of {self.name} ({exc}); this is "
                                 "said once")
                query.reply_err(f"not a request of {self.name}: {exc}")
                return
        with self._lock:
            proxy = self._idle.pop() if self._idle else None
        if proxy is None:
            proxy = minros.ServiceProxy(self.name, self.service_class, persistent=True)
        try:
            response = proxy.call(self.service_class._request_class(data))
        except Exception as exc:  # noqa: BLE001 - every failure is the caller's answer
            proxy.close()
            query.reply_err(_server_error(self.name, str(exc)))
            return
        with self._lock:
            if len(self._idle) < IDLE_PROXIES:
                self._idle.append(proxy)
                proxy = None
        if proxy is not None:
            proxy.close()
        query.reply(self.key, bytes(response._buff))

    def close(self) -> None:
        self.queryable.undeclare()
        with self._lock:
            idle, self._idle = self._idle, []
        for proxy in idle:
            proxy.close()


class Proxy:
    """A remote service offered here: a local service whose handler queries Zenoh."""

    def __init__(self, bridge: Bridge, topic: Topic) -> None:
        name, type_name, md5 = topic
        self.bridge = bridge
        self.name = name
        self.key = keys.data_key(name, type_name, md5, bridge.options.namespace)
        self.service_class = raw_service_class(type_name, md5)
        self.check = bridge.service_checker(type_name, md5, "Response")
        self.service = minros.Service(name, self.service_class, self._handle)

    def _handle(self, request: Any) -> Any:
        timeout = self.bridge.options.service_timeout
        replies = self.bridge.session.get(self.key, payload=bytes(request._buff), timeout=timeout,
                                          allowed_destination=zenoh.Locality.REMOTE)
        for reply in replies:
            if reply.ok is None:
                raise ServiceException(_strip_prefix(reply.err.payload.to_string()))
            data = reply.ok.payload.to_bytes()
            if self.check is not None:
                try:
                    self.check(data)
                except layout.Malformed as exc:
                    # zenoh-bridge-ros1 sends a failed call's error text as the reply itself
                    text = _text(data)
                    if text is not None:
                        raise ServiceException(_strip_prefix(text)) from None
                    raise ServiceException(f"the answer from Zenoh is not a response of "
                                           f"{self.name}: {exc}") from None
            return self.service_class._response_class(data)
        raise ServiceException(f"no answer from Zenoh on {self.key} within {timeout:g} s")

    def close(self) -> None:
        self.service.shutdown()


_PREFIX = "service cannot process request: "


def _server_error(name: str, text: str) -> str:
    """The error string the server sent, out of ServiceProxy's "service [name] responded
    with an error: b'...'" (so the far client reads what a direct call would); other
    failures (unavailable, transport) as they are."""
    import ast

    lead = f"service [{name}] responded with an error: "
    if text.startswith(lead):
        try:
            raw = ast.literal_eval(text[len(lead):])
            if isinstance(raw, bytes):
                return raw.decode("utf-8", "replace")
        except (ValueError, SyntaxError):
            pass
    return text


def _strip_prefix(text: str) -> str:
    """A server's error without rospy's prefix, which the local Service adds back once."""
    return text[len(_PREFIX):] if text.startswith(_PREFIX) else text


def _text(data: bytes) -> Optional[str]:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return None
    return text if text.isprintable() and text else None


# -- the bridge ---------------------------------------------------------------------------------


@dataclass
class _Round:
    """One control round's creation budget: its deadline, the first-heard times, and how
    many bridges it left for later."""

    deadline: float
    first_heard: Dict[Topic, float]
    deferred: int = 0


class Bridge:
    """Bridges the master the node is attached to with a Zenoh network."""

    def __init__(self, options: Options, log: Callable[[str], None] = minros.logwarn,
                 info: Callable[[str], None] = minros.loginfo) -> None:
        keys.check_namespace(options.namespace)
        self.options = options
        self.log = log
        self.info = info
        self.once = OnceLog(log)
        try:
            self.session = zenoh.open(zenoh_config(options))
        except zenoh.ZError as exc:
            raise BridgeError(f"cannot open the Zenoh session: {exc}".split(" at /")[0]) from None
        self.remote = RemoteTable()
        self.declarations = Declarations(options.namespace)
        self.graph = LocalGraph(minros.get_name(), get_master_uri(),
                                lambda text: self.once(text))
        self.pool = ThreadPoolExecutor(max_workers=8, thread_name_prefix="minros-zenoh-call")
        self._pending_calls = 0
        self._calls_lock = threading.Lock()
        self.bounds = BoundLog(log)
        self.chatter = Chatter(info)
        self.rate = TokenBucket(options.create_rate, max(CREATE_BURST, options.create_rate),
                                time.monotonic())
        self.snapshot: Optional[Snapshot] = None
        self.outlets: Dict[Topic, Outlet] = {}
        self.inlets: Dict[Topic, Inlet] = {}
        self.queryables: Dict[Topic, Queryable] = {}
        self.proxies: Dict[Topic, Proxy] = {}
        self._beacons: Dict[str, Any] = {}
        self._retry: Dict[Tuple[str, Topic], float] = {}
        self._round = _Round(0.0, {})
        self._checkers: Dict[Tuple[str, str, str], Optional[Callable[[Any], None]]] = {}
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._master_down = False
        self._threads: List[threading.Thread] = []
        self._discovery = self.session.declare_subscriber(
            keys.discovery_subscription(options.namespace), _direct(self._on_beacon))

    @property
    def zid(self) -> str:
        return str(self.session.info.zid())

    def start(self) -> None:
        for target, name in ((self._graph_loop, "minros-zenoh-graph"),
                             (self._control_loop, "minros-zenoh-control")):
            thread = threading.Thread(target=target, name=name, daemon=True)
            thread.start()
            self._threads.append(thread)

    def stop(self) -> None:
        """Remove every bridge, stop the beacons and close the session."""
        self._stop.set()
        self._wake.set()
        for thread in self._threads:
            thread.join(5.0)
        for table in (self.inlets, self.outlets, self.queryables, self.proxies):
            for obj in table.values():
                try:
                    obj.close()
                except Exception:  # noqa: BLE001 - closing anyway
                    pass
            table.clear()
        self.pool.shutdown(wait=False, cancel_futures=True)
        self.graph.close()
        try:
            self.session.close()
        except Exception:  # noqa: BLE001
            pass

    # -- Zenoh callbacks ---------------------------------------------------------------------

    def _on_beacon(self, sample: Any) -> None:
        key = str(sample.key_expr)
        now = time.monotonic()
        try:
            if self.remote.heard(key, now) is not None:
                self._wake.set()
        except TableFull:
            self.bounds("table", f"more than {self.remote.max_entries} remote resources are "
                        f"declared to this bridge: ignoring the new ones (such as [{key[:200]}]) "
                        "until some are lost", now)
        except KeyMappingError as exc:
            self.once(f"beacon {key}", f"ignoring beacons on {key}: {exc}")

    def submit_call(self, fn: Callable[[Any], None], query: Any) -> bool:
        """Run a service call from Zenoh in the pool; False when too many wait already."""
        with self._calls_lock:
            if self._pending_calls >= MAX_PENDING_CALLS:
                full = True
            else:
                full = False
                self._pending_calls += 1
        if full:
            self.bounds("calls", f"{MAX_PENDING_CALLS} service calls from Zenoh are waiting: "
                        "new ones are refused until they are answered", time.monotonic())
            return False

        def run() -> None:
            try:
                fn(query)
            finally:
                with self._calls_lock:
                    self._pending_calls -= 1
        try:
            self.pool.submit(run)
        except RuntimeError:  # shutting down
            with self._calls_lock:
                self._pending_calls -= 1
            return False
        return True

    # -- the graph thread ---------------------------------------------------------------------

    def _graph_loop(self) -> None:
        while not self._stop.is_set():
            try:
                snapshot = self.graph.read(self.remote.resources())
            except OSError as exc:
                if not self._master_down:
                    self._master_down = True
                    self.log(f"the ROS master does not answer ({exc}); the bridges stay as "
                             "they are until it does")
            except Exception as exc:  # noqa: BLE001 - a bug must not stop the bridge
                self.once(f"graph {exc}", f"reading the ROS graph failed: {exc!r}")
            else:
                if self._master_down:
                    self._master_down = False
                    self.info("the ROS master answers again")
                if snapshot != self.snapshot:
                    self.snapshot = snapshot
                    self._wake.set()
            self._stop.wait(self.options.poll_interval)

    # -- the control thread -------------------------------------------------------------------

    def _control_loop(self) -> None:
        while not self._stop.is_set():
            self._wake.wait(TICK)
            self._wake.clear()
            if self._stop.is_set():
                break
            try:
                self.step(time.monotonic())
            except Exception as exc:  # noqa: BLE001
                self.once(f"control {exc}", f"bridging failed: {exc!r}")

    def step(self, now: float) -> Plan:
        """One round: forget silent remote resources, bridge what the plan says, beacon."""
        for lost in self.remote.expire(now):
            self.chatter(f"lost remote {lost.kind} {lost.name} ({lost.type})", now)
        snapshot = self.snapshot
        local = snapshot.resources if snapshot is not None else frozenset()
        remote = self.remote.resources()
        first_heard = self.remote.first_heard()
        wanted, left_out = limit_remote(plan(local, remote), local, first_heard,
                                        self.options.max_remote)
        for text in wanted.conflicts:
            self.once(text)
        if left_out:
            self.bounds("count", f"remote bridges are at their bound of "
                        f"{self.options.max_remote}: {left_out} more topics and services "
                        "declared by remote beacons alone are not bridged (the first heard "
                        "are kept; --max-remote raises the bound)", now)
        only = remote_only(wanted, local)
        publishers = snapshot.publishers if snapshot is not None else {}
        self._round = _Round(now + CREATE_BUDGET, first_heard)
        self._sync("inlet", self.inlets, wanted.inlets, now,
                   lambda t: Inlet(self, t, threaded=t not in only["inlets"]), "Zenoh -> ROS",
                   only["inlets"])
        for topic, inlet in self.inlets.items():
            if not inlet.threaded and topic not in only["inlets"]:
                inlet.thread()
        self._sync("outlet", self.outlets, wanted.outlets, now,
                   lambda t: Outlet(self, t, publishers.get(t)), "ROS -> Zenoh", only["outlets"])
        self._upgrade_inlets(remote)
        self._sync("queryable", self.queryables, wanted.queryables, now,
                   lambda t: Queryable(self, t), "service ROS -> Zenoh", frozenset())
        self._sync("proxy", self.proxies, wanted.proxies, now,
                   lambda t: Proxy(self, t), "service Zenoh -> ROS", only["proxies"])
        if self._round.deferred:
            self.bounds("rate", f"bridges for remote beacons are made at most "
                        f"{self.options.create_rate:g} a second and {CREATE_BUDGET} s a round: "
                        f"{self._round.deferred} wait for the next rounds", now)
        kept = {(k, t) for k, table in (("inlet", wanted.inlets), ("outlet", wanted.outlets),
                                        ("queryable", wanted.queryables),
                                        ("proxy", wanted.proxies)) for t in table}
        for stale in [k for k in self._retry if k not in kept]:
            del self._retry[stale]
        self.declarations.update(wanted.declare, now)
        self._send_beacons(now)
        return wanted

    def _sync(self, kind: str, current: Dict[Topic, Any], wanted: Any, now: float,
              make: Callable[[Topic], Any], direction: str, beacon_only: Any) -> None:
        """Close what is no longer wanted; make what is newly wanted: what the local graph
        asks for first, then what remote beacons alone ask for, the first heard first, one
        token of the creation rate each; none once the round's time budget is spent."""
        def said(text: str, topic: Topic) -> None:
            if topic in beacon_only or topic not in wanted:
                self.chatter(text, now)  # a peer's flood must not flood the log
            else:
                self.info(text)

        for topic in [t for t in current if t not in wanted]:
            obj = current.pop(topic)
            try:
                obj.close()
            except Exception as exc:  # noqa: BLE001
                self.once(f"close {kind} {topic} {exc}", f"closing the bridge of {topic[0]}: {exc}")
            said(f"stopped bridging {topic[0]} ({topic[1]}) {direction}", topic)
        first = self._round.first_heard
        new = sorted((t for t in wanted if t not in current),
                     key=lambda t: (t in beacon_only, first.get(t, 0.0), t))
        for topic in new:
            if self._retry.get((kind, topic), 0.0) > now:
                continue
            if time.monotonic() > self._round.deadline:
                self._round.deferred += 1
                continue
            if topic in beacon_only and not self.rate.take(time.monotonic()):
                self._round.deferred += 1
                continue
            try:
                current[topic] = make(topic)
            except Exception as exc:  # noqa: BLE001 - tried again after RETRY
                self._retry[(kind, topic)] = now + RETRY
                self.once(f"make {kind} {topic} {exc}",
                          f"cannot bridge {topic[0]} ({topic[1]}) {direction}: {exc}")
                continue
            self._retry.pop((kind, topic), None)
            said(f"bridging {topic[0]} ({topic[1]}) {direction}", topic)

    def ask_meta(self, topic: Topic) -> Optional[meta.TopicMeta]:
        """The record a minros bridge publishing ``topic`` answers with, or None (no minros
        bridge publishes it, or only zenoh-bridge-ros1 does)."""
        name, type_name, md5 = topic
        key = keys.meta_key(name, type_name, md5, self.options.namespace)
        try:
            replies = self.session.get(key, timeout=META_TIMEOUT,
                                       allowed_destination=zenoh.Locality.REMOTE)
            for reply in replies:
                if reply.ok is None:
                    continue
                try:
                    record = meta.decode(reply.ok.payload.to_bytes())
                except meta.MetaError as exc:
                    self.once(f"meta {reply.ok.key_expr}",
                              f"ignoring the topic record on {reply.ok.key_expr}: {exc}")
                    continue
                if (record.type, record.md5sum) == (type_name, md5):
                    return record
        except zenoh.ZError as exc:
            self.once(f"meta query {exc}", f"cannot query {key}: {exc}")
        return None

    def _upgrade_inlets(self, remote: Any) -> None:
        """An inlet made for a local subscriber before any remote publisher existed has no
        definition or latching from it; once a remote publisher appears, ask it."""
        published = {r.topic for r in remote if r.kind == "pub"}
        for topic, inlet in list(self.inlets.items()):
            if inlet.record is not None or topic not in published:
                continue
            record = self.ask_meta(topic)
            if record is None:
                inlet.record = meta.TopicMeta(topic[1], topic[2])  # asked: no minros peer
                continue
            if record.latching or (record.definition and not inlet.definition):
                del self.inlets[topic]
                inlet.close()
                try:
                    self.inlets[topic] = Inlet(self, topic, threaded=inlet.threaded)
                except Exception as exc:  # noqa: BLE001 - the next step makes it again
                    self.once(f"remake {topic} {exc}", f"cannot bridge {topic[0]}: {exc}")
            else:
                inlet.record = record

    def _send_beacons(self, now: float) -> None:
        wanted = set(self.declarations.keys())
        for key in [k for k in self._beacons if k not in wanted]:
            self._beacons.pop(key).undeclare()
        for key in self.declarations.due(now):
            publisher = self._beacons.get(key)
            if publisher is None:
                publisher = self.session.declare_publisher(
                    key, reliability=zenoh.Reliability.BEST_EFFORT,
                    congestion_control=zenoh.CongestionControl.DROP,
                    priority=zenoh.Priority.BACKGROUND, allowed_destination=zenoh.Locality.REMOTE)
                self._beacons[key] = publisher
            publisher.put(b"")

    # -- checks ------------------------------------------------------------------------------

    def checker(self, type_name: str, md5: str, definition: str,
                name: str) -> Optional[Callable[[Any], None]]:
        """A layout check for messages of ``type_name``: from the installed definition when its
        md5sum matches, else from the carried definition; None (one line) without either."""
        key = ("msg", type_name, md5)
        if key not in self._checkers:
            self._checkers[key] = self._make_checker(type_name, md5, definition)
            if self._checkers[key] is None:
                self.once(f"unchecked {type_name} {md5}",
                          f"samples of {type_name} ({name}) go to ROS unchecked: its definition "
                          "is neither installed here nor sent by a minros bridge")
        return self._checkers[key]

    @staticmethod
    def _make_checker(type_name: str, md5: str, definition: str) -> Optional[Callable[[Any], None]]:
        from minros.msgs import generate_dynamic, get_message_class

        try:
            cls = get_message_class(type_name)
            if cls._md5sum == md5:
                return layout.checker(type_name, lambda t: list(get_message_class(t)._slot_types))
        except Exception:  # noqa: BLE001 - not installed (or broken): try the carried text
            pass
        if definition:
            try:
                classes = generate_dynamic(type_name, definition)
                if classes[type_name]._md5sum == md5:
                    return layout.checker(type_name, layout.slot_types_from_classes(classes))
            except Exception:  # noqa: BLE001
                return None
        return None

    def service_checker(self, type_name: str, md5: str, part: str) -> Optional[Callable[[Any], None]]:
        """A layout check of a service's requests or responses (``part``), when installed."""
        key = (part, type_name, md5)
        if key not in self._checkers:
            from minros.msgs import get_message_class, get_service_class

            check = None
            try:
                srv = get_service_class(type_name)
                if srv._md5sum == md5:
                    cls = getattr(srv, f"_{part.lower()}_class")
                    check = layout.checker(cls._type, lambda t: list(
                        (cls if t == cls._type else get_message_class(t))._slot_types))
            except Exception:  # noqa: BLE001 - not installed: passed unchecked
                check = None
            self._checkers[key] = check
        return self._checkers[key]

    # -- what users see ----------------------------------------------------------------------

    def status(self) -> Dict[str, List[str]]:
        """The bridged names by kind (for tests and the banner)."""
        return {"outlets": sorted(t[0] for t in self.outlets),
                "inlets": sorted(t[0] for t in self.inlets),
                "queryables": sorted(t[0] for t in self.queryables),
                "proxies": sorted(t[0] for t in self.proxies),
                "remote": sorted(f"{r.kind} {r.name}" for r in self.remote.resources())}



# -- the program ----------------------------------------------------------------------------------


def master_error() -> Optional[str]:
    """Why the master cannot be used, or None."""
    from minros.tools.master import Master, MasterIOError

    master = Master("/minros_zenoh")
    try:
        master.getPid()
        return None
    except MasterIOError:
        return (f"cannot reach the ROS master at {master.uri}: start one with `minros core` "
                "(or roscore), or set ROS_MASTER_URI")
    except Exception as exc:  # noqa: BLE001
        return f"the ROS master at {master.uri} does not answer: {exc}"
    finally:
        master.close()


def run(options: Options, name: str = "minros_zenoh", announce: Callable[[str], None] = print,
        argv: Optional[List[str]] = None) -> int:
    """Start the node and the bridge; bridge until Ctrl-C or a ROS shutdown. Exit status."""
    import signal
    import sys

    from minros.signals import SignalWatch

    error = master_error()
    if error:
        print(f"minros zenoh: error: {error}", file=sys.stderr)
        return 1
    zenoh.try_init_log_from_env()  # Zenoh's own log only when RUST_LOG asks for it
    minros.init_node(name, argv=argv, disable_signals=True)
    stop = threading.Event()
    SignalWatch(lambda _signum: stop.set(), "zenoh-signals").install((signal.SIGINT, signal.SIGTERM))
    minros.on_shutdown(stop.set)
    try:
        bridge = Bridge(options)
    except (BridgeError, KeyMappingError) as exc:
        print(f"minros zenoh: error: {exc}", file=sys.stderr)
        minros.signal_shutdown("cannot start")
        return 1
    bridge.start()
    where = [f"mode {options.mode}", f"namespace {options.namespace}"]
    if options.listen:
        where.append("listening on " + " ".join(options.listen))
    if options.connect:
        where.append("connecting to " + " ".join(options.connect))
    if not options.multicast_scouting:
        where.append("no multicast scouting")
    announce(f"minros zenoh: bridging the master at {get_master_uri()} as "
             f"{minros.get_name()} with Zenoh as {bridge.zid} ({', '.join(where)})")
    try:
        while not stop.wait(0.5):
            if minros.is_shutdown():
                break
    finally:
        bridge.stop()
        minros.signal_shutdown("minros zenoh stopped")
    return 0
