"""The ROS side of ``minros web``: one object owns everything the server knows about the graph.

:class:`WebState` is the web server's node on the ROS graph. It holds, each in one place:

* the graph as the master last told it (topics and types, publishers, subscribers, services,
  service types), refreshed by one thread and pushed to whoever listens (Foxglove sessions, the
  web page). The master pushes: minros's master calls ``graphUpdate`` on a small XML-RPC
  endpoint of ours (:class:`GraphPush`) after every registration change, and the thread reads
  the graph then; Debian's rosmaster has no ``subscribeGraph``, so against it the thread reads
  the graph every ``graph_interval`` seconds instead (``graph_mode`` says which);
* the parameters, for listeners (Foxglove, the page): one ``subscribeParam('/')`` of the node,
  so the master pushes every change with ``paramUpdate`` (any master has that);
* the *taps*: one raw subscriber per topic however many clients want it. A tap receives the
  TCPROS message bytes unchanged (an ``AnyMsg``-style class, so nothing is deserialized for
  clients that forward bytes) and hands one shared :class:`Incoming` to every listener; whatever
  a listener derives from it (decoded message, rosbridge JSON, CBOR) is computed once and cached
  on it for the others. Taps count messages and bytes for the topic statistics;
* the publishers clients publish through, shared per topic and released a while after their
  last client leaves (rosbridge's ``unregister_timeout``), messages of the first second replayed
  to subscribers that connect late (rosbridge's PublisherConsistencyListener);
* service type discovery, service calls (typed, or raw bytes for Foxglove), parameters, time;
* the image feeds of the video endpoints (see :mod:`minros.web.video`).

Sessions (rosbridge, Foxglove, video viewers) only talk to this object; it talks to ROS through
the ``minros`` facade and ``minros.tools``.
"""

from __future__ import annotations

import fnmatch
import io
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, Hashable, List, Optional, Set, Tuple

import minros
from minros.msgs import reader_for
from minros.tools.services import probe_service
from minros.web.rosapi import Graph

#: seconds between two readings of the master's graph when it cannot push (rosmaster)
DEFAULT_GRAPH_INTERVAL = 1.0
#: seconds between two subscribeGraph calls while pushed to (they renew the subscription, so a
#: restarted master pushes again, and tell a version we may have missed)
GRAPH_RENEW_INTERVAL = 5.0
#: registrations arriving within this many seconds of a push are read with it
GRAPH_SETTLE = 0.02
#: rosbridge's unregister_timeout: a publisher outlives its last client by this long
DEFAULT_UNREGISTER_TIMEOUT = 10.0
#: messages published in a publisher's first second are replayed to late subscribers
CONSISTENCY_WINDOW = 1.0
PROBE_TIMEOUT = 2.0


# -- raw message classes -------------------------------------------------------------------

_RAW_CLASSES: Dict[Tuple[str, str], type] = {}


def raw_class(type_name: str, md5sum: str, definition: str) -> type:
    """A message class that keeps the serialized bytes (``_buff``) of ``type_name``.

    Subscribing with it asks publishers for the real type and md5 (so the master lists the
    real type) and receives the TCPROS bytes as they are; publishing it sends the bytes as
    they are.
    """
    key = (type_name, md5sum)
    cls = _RAW_CLASSES.get(key)
    if cls is None:
        cls = type("Raw_" + type_name.replace("/", "_"), (minros.AnyMsg,),
                   {"_type": type_name, "_md5sum": md5sum, "_full_text": definition,
                    "_has_header": False, "__slots__": ()})
        _RAW_CLASSES[key] = cls
    return cls


def raw_service_class(type_name: str, md5sum: str) -> type:
    """A service class whose request and response are raw bytes (Foxglove service calls)."""
    request = raw_class(type_name + "Request", md5sum, "")
    response = raw_class(type_name + "Response", md5sum, "")
    return type("RawService", (), {"_type": type_name, "_md5sum": md5sum,
                                   "_request_class": request, "_response_class": response})


# -- what taps hand out --------------------------------------------------------------------

class Incoming:
    """One message received on a tapped topic, shared by all the clients that get it."""

    __slots__ = ("tap", "data", "header", "receive_ns", "_cache", "__weakref__")

    def __init__(self, tap: TopicTap, data: Any, header: Dict[str, str], receive_ns: int) -> None:
        self.tap = tap
        self.data = data
        self.header = header
        self.receive_ns = receive_ns
        self._cache: Dict[Hashable, Any] = {}

    @property
    def size(self) -> int:
        return len(self.data)

    def cached(self, key: Hashable, make: Callable[[], Any]) -> Any:
        """``make()`` once per key for every client (two threads may both compute it; both
        results are equal, and the dict write is atomic)."""
        try:
            return self._cache[key]
        except KeyError:
            value = make()
            self._cache[key] = value
            return value

    def decoded(self) -> Any:
        """The message as an instance of its type (the installed class, or one generated from
        the publisher's definition)."""
        return self.cached("decoded", self._decode)

    def _decode(self) -> Any:
        # from the bytes, without a default instance first (the publisher chose the type's
        # definition: its fixed-size arrays may be huge where the message is short)
        return _reader(self.tap.state.decoder.class_for_header(self.header))(self.data)


_READERS: Dict[type, Callable[[Any], Any]] = {}


def _reader(cls: type) -> Callable[[Any], Any]:
    read = _READERS.get(cls)
    if read is None:
        read = _READERS[cls] = reader_for(cls)
    return read


class TopicTap:
    """The one subscription of the web node on a topic: a subscription of the state's
    :class:`~minros.web.receiver.Receiver` (no thread of its own), or a Subscriber where the
    node has one already (/clock on simulated time, a dynamic_reconfigure client's topics).
    Listeners are called in the receiving thread and must only queue (no I/O)."""

    def __init__(self, state: WebState, topic: str, data_class: type) -> None:
        self.state = state
        self.topic = topic
        self.data_class = data_class
        self.listeners: Dict[Hashable, Callable[[Incoming], None]] = {}
        self.lock = threading.Lock()
        self.count = 0
        self.bytes = 0
        self.last_ns = 0
        self.header: Dict[str, str] = {}
        # the last message of each latching publisher, for listeners that come later: the one
        # subscription is shared, so a second client would otherwise never see a latched
        # message (rosbridge's shared subscriber keeps it too)
        self.latched: Dict[str, Incoming] = {}
        self._times: List[float] = []
        self.subscriber: Any = None
        self.raw: Any = None
        try:
            self.raw = state.receiver().subscribe(topic, data_class, self._deliver)
        except ValueError:  # the node subscribes there itself: share its Subscriber
            self.use_subscriber()

    def use_subscriber(self) -> None:
        """Receive through a Subscriber from now on, which other code of the node shares: with
        the type's own class when there is one, since the first Subscriber of a topic picks
        the class every callback gets (``_callback`` takes either)."""
        raw, self.raw = self.raw, None
        if raw is not None:
            self.state.receiver().unsubscribe(raw)
        if self.subscriber is None:
            cls = self.data_class
            if cls._type not in ("", "*"):
                try:
                    cls = self.state.message_class(cls._type)
                except Exception:  # a type only the publisher knows: bytes it is
                    cls = self.data_class
            self.subscriber = minros.Subscriber(self.topic, cls, self._callback, tcp_nodelay=True)

    @property
    def type(self) -> str:
        return self.header.get("type") or (self.data_class._type if self.data_class._type != "*" else "")

    def _callback(self, msg: Any) -> None:
        """A Subscriber's message: the bytes as received (a raw class), or, when code of the
        node subscribed first with the type's class (/clock, dynamic_reconfigure), the
        message serialized again."""
        data = getattr(msg, "_buff", None)
        if data is None:
            buff = io.BytesIO()
            msg.serialize(buff)
            data = buff.getvalue()
        self._deliver(data, getattr(msg, "_connection_header", None) or {})

    def _deliver(self, data: Any, header: Dict[str, str]) -> None:
        self.header = header
        now_ns = self.state.now_ns()
        incoming = Incoming(self, data, header, now_ns)
        if header.get("latching") == "1":
            self.latched[header.get("callerid", "")] = incoming
        self.count += 1
        self.bytes += len(data)
        self.last_ns = now_ns
        times = self._times
        times.append(time.monotonic())
        if len(times) > 200:
            del times[:100]
        for listener in list(self.listeners.values()):
            try:
                listener(incoming)
            except Exception as exc:  # one client's bug must not starve the others
                minros.logerr(f"[web] listener on {self.topic} failed: {exc}")

    def rate(self) -> float:
        """Messages per second over the last few seconds (0 when idle)."""
        times = self._times[-100:]
        if len(times) < 2 or time.monotonic() - times[-1] > 2.0:
            return 0.0
        return (len(times) - 1) / (times[-1] - times[0]) if times[-1] > times[0] else 0.0

    def add(self, key: Hashable, listener: Callable[[Incoming], None]) -> None:
        with self.lock:
            self.listeners = {**self.listeners, key: listener}
            latched = list(self.latched.values())
        for incoming in latched:
            listener(incoming)

    def remove(self, key: Hashable) -> bool:
        """Drop a listener; True when none is left."""
        with self.lock:
            listeners = dict(self.listeners)
            listeners.pop(key, None)
            self.listeners = listeners
            return not listeners

    def close(self) -> None:
        if self.raw is not None:
            self.state.receiver().unsubscribe(self.raw)
        if self.subscriber is not None:
            self.subscriber.unregister()


# -- publishers shared by clients ----------------------------------------------------------

class _Replay(minros.SubscribeListener):
    """Replays the messages of a publisher's first second to subscribers that connect late, so a
    client's first messages are not lost to connection setup (rosbridge does the same)."""

    def __init__(self) -> None:
        self.started = time.monotonic()
        self.buffer: List[Any] = []
        self.lock = threading.Lock()

    def fresh(self) -> bool:
        return time.monotonic() - self.started < CONSISTENCY_WINDOW

    def record(self, msg: Any) -> None:
        if self.fresh():
            with self.lock:
                if len(self.buffer) < 1000:
                    self.buffer.append(msg)

    def peer_subscribe(self, topic_name: str, topic_publish: Callable, peer_publish: Callable) -> None:
        if self.fresh():
            with self.lock:
                pending = list(self.buffer)
            for msg in pending:
                peer_publish(msg)


class SharedPublisher:
    def __init__(self, topic: str, data_class: type, latch: bool, queue_size: int) -> None:
        self.topic = topic
        self.data_class = data_class
        self.latch = latch
        self.replay = _Replay()
        self.publisher = minros.Publisher(topic, data_class, subscriber_listener=self.replay,
                                          latch=latch, queue_size=queue_size)
        self.clients: Set[Hashable] = set()
        self.timer: Optional[threading.Timer] = None

    def publish(self, msg: Any) -> None:
        self.replay.record(msg)
        self.publisher.publish(msg)


# -- the master's pushes ---------------------------------------------------------------------

class _GraphUpdates:
    """The XML-RPC API the master calls (only ``graphUpdate``)."""

    def __init__(self, on_update: Callable[[], None]) -> None:
        self._on_update = on_update

    def graphUpdate(self, caller_id: str, version: int) -> List[Any]:
        self._on_update()
        return [1, "", 0]


class GraphPush:
    """An XML-RPC endpoint of our own for ``graphUpdate`` calls (not the node's slave API, whose
    methods stay exactly rospy's); ``on_update()`` runs in the server's connection thread."""

    def __init__(self, on_update: Callable[[], None]) -> None:
        from minros import rosenv
        from minros.wire.xmlrpc import XmlRpcServer

        self.server = XmlRpcServer(_GraphUpdates(on_update), rosenv.get_bind_address(), 0,
                                   max_connections=8)
        self.server.start()
        self.uri = rosenv.create_local_xmlrpc_uri(self.server.port)

    def close(self) -> None:
        self.server.shutdown()


# -- the state -----------------------------------------------------------------------------

@dataclass
class Options:
    topics_glob: List[str] = field(default_factory=list)
    services_glob: List[str] = field(default_factory=list)
    params_glob: List[str] = field(default_factory=list)
    graph_interval: float = DEFAULT_GRAPH_INTERVAL
    unregister_timeout: float = DEFAULT_UNREGISTER_TIMEOUT


class WebState:
    """Everything ``minros web`` knows about and does on the ROS graph (see the module doc)."""

    def __init__(self, options: Optional[Options] = None) -> None:
        from minros.tools.decode import Decoder
        from minros.tools.master import Master

        self.options = options or Options()
        self.caller_id = minros.get_caller_id()
        self.master = Master(self.caller_id)
        self._master_lock = threading.Lock()
        self.decoder = Decoder()
        self.lock = threading.RLock()
        self.graph = Graph()
        self.graph_version = 0
        self._graph_listeners: Dict[Hashable, Callable[[Graph], None]] = {}
        self._service_types: Dict[Tuple[str, Tuple[str, ...]], str] = {}
        self.taps: Dict[str, TopicTap] = {}
        self._receiver: Any = None
        self.publishers: Dict[str, SharedPublisher] = {}
        self.channel_ids: Dict[Tuple[str, str], int] = {}
        self.service_ids: Dict[Tuple[str, str], int] = {}
        self.feeds: Dict[str, Any] = {}
        self.param_listeners: Dict[Hashable, Callable[[Dict[str, Any], List[str]], None]] = {}
        self._params: Optional[Dict[str, Any]] = None
        self.use_sim_time = bool(self.get_param("/use_sim_time", False))
        self._params_subscribed = False
        self._param_handler_added = False
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: Optional[threading.Thread] = None
        self._push: Optional[GraphPush] = None
        #: "push" while the master tells us about changes, "poll" otherwise (rosmaster); ""
        #: before start()
        self.graph_mode = ""
        self._renewed = 0.0
        self.started = time.time()

    # -- lifecycle -------------------------------------------------------------------------

    def start(self) -> None:
        """Ask the master to push graph changes, read the graph, start the graph thread."""
        try:
            self._push = GraphPush(self._wake.set)
        except OSError as exc:
            minros.logwarn(f"[web] cannot listen for the master's graph pushes ({exc})")
        self._renew_graph_push()
        self.refresh_graph()
        self._thread = threading.Thread(target=self._graph_loop, name="minros-web-graph",
                                        daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._push is not None:
            try:
                self._call("unsubscribeGraph", self._push.uri)
            except Exception:
                pass  # the master is gone: it forgets us on the next failed push anyway
            self._push.close()
        with self.lock:
            taps, self.taps = list(self.taps.values()), {}
            pubs, self.publishers = list(self.publishers.values()), {}
        for tap in taps:
            tap.close()
        if self._receiver is not None:
            self._receiver.close()
        for pub in pubs:
            if pub.timer:
                pub.timer.cancel()
            pub.publisher.unregister()

    def poke(self) -> None:
        """Read the graph again now (a client connected, or advertised something)."""
        self._wake.set()

    def _renew_graph_push(self) -> None:
        """subscribeGraph (again), which sets ``graph_mode``."""
        self._renewed = time.monotonic()
        mode = "poll"
        if self._push is not None:
            try:
                self._call("subscribeGraph", self._push.uri)
                mode = "push"
            except Exception as exc:  # rosmaster: no such method; or the master is away
                minros.logdebug(f"[web] the master does not push graph changes: {exc}")
        if mode != self.graph_mode:
            self.graph_mode = mode
            minros.loginfo("[web] graph: " + ("pushed by the master" if mode == "push" else
                                               f"read every {self.options.graph_interval:g} s"))

    def _graph_loop(self) -> None:
        while not self._stop.is_set() and not minros.is_shutdown():
            push = self.graph_mode == "push"
            woken = self._wake.wait(GRAPH_RENEW_INTERVAL if push else self.options.graph_interval)
            self._wake.clear()
            if woken and push:
                self._stop.wait(GRAPH_SETTLE)  # let a burst of registrations land
                self._wake.clear()
            if self._stop.is_set():
                return
            try:
                if time.monotonic() - self._renewed >= GRAPH_RENEW_INTERVAL:
                    self._renew_graph_push()
                self.refresh_graph()
                if self.param_listeners and not self._params_subscribed:
                    self._subscribe_params()
            except Exception as exc:  # the master may be restarting: try again next round
                minros.logdebug(f"[web] graph refresh failed: {exc}")

    # -- the graph -------------------------------------------------------------------------

    def _call(self, method: str, *args: Any) -> Any:
        with self._master_lock:
            return self.master.call(method, *args)

    def refresh_graph(self) -> Graph:
        """Ask the master now; listeners hear about a changed graph."""
        topic_types = self._call("getTopicTypes")
        pubs, subs, srvs = self._call("getSystemState")
        graph = Graph(topic_types={t: ty for t, ty in topic_types},
                      publishers={t: list(n) for t, n in pubs},
                      subscribers={t: list(n) for t, n in subs},
                      services={s: list(n) for s, n in srvs})
        with self.lock:
            changed = graph != self.graph
            self.graph = graph
            if changed:
                self.graph_version += 1
            listeners = list(self._graph_listeners.values())
        if changed:
            for listener in listeners:
                try:
                    listener(graph)
                except Exception as exc:
                    minros.logerr(f"[web] graph listener failed: {exc}")
        return graph

    def read_graph(self) -> Graph:
        """The graph as the master has it now (rosapi asks the master on every call)."""
        return self.refresh_graph()

    def add_graph_listener(self, key: Hashable, listener: Callable[[Graph], None]) -> None:
        with self.lock:
            self._graph_listeners[key] = listener

    def remove_graph_listener(self, key: Hashable) -> None:
        with self.lock:
            self._graph_listeners.pop(key, None)

    def topic_type(self, topic: str) -> Optional[str]:
        """The type the master has for ``topic`` (asked again when not known yet)."""
        found = self.graph.topic_types.get(topic)
        if not found or found == "*":
            found = self.refresh_graph().topic_types.get(topic)
        return found if found and found != "*" else None

    def topic_allowed(self, topic: str) -> bool:
        globs = self.options.topics_glob
        return not globs or any(fnmatch.fnmatch(topic, g) for g in globs)

    def service_allowed(self, name: str) -> bool:
        globs = self.options.services_glob
        return not globs or any(fnmatch.fnmatch(name, g) for g in globs)

    def service_uri(self, service: str) -> Optional[str]:
        from minros.tools.master import MasterError

        try:
            return self._call("lookupService", service)
        except MasterError:
            return None

    def service_header(self, service: str) -> Dict[str, str]:
        uri = self.service_uri(service)
        if uri is None:
            raise LookupError(f"Service {service} does not exist")
        return probe_service(uri, service, self.caller_id, PROBE_TIMEOUT)

    def service_type(self, service: str) -> str:
        """The type of ``service`` from its server's probe header (cached per provider)."""
        key = (service, tuple(self.graph.services.get(service, ())))
        cached = self._service_types.get(key)
        if cached:
            return cached
        found = self.service_header(service).get("type", "")
        if found and key[1]:
            self._service_types[key] = found
        return found

    # -- ids the Foxglove protocol hands out -----------------------------------------------

    def channel_id(self, topic: str, type_name: str) -> int:
        with self.lock:
            key = (topic, type_name)
            if key not in self.channel_ids:
                self.channel_ids[key] = len(self.channel_ids) + 1
            return self.channel_ids[key]

    def service_id(self, name: str, type_name: str) -> int:
        with self.lock:
            key = (name, type_name)
            if key not in self.service_ids:
                self.service_ids[key] = len(self.service_ids) + 1
            return self.service_ids[key]

    # -- taps ------------------------------------------------------------------------------

    def receiver(self) -> Any:
        """The node's :class:`~minros.web.receiver.Receiver` (started on first use)."""
        with self.lock:
            if self._receiver is None:
                from minros.web.receiver import Receiver

                self._receiver = Receiver()
            return self._receiver

    def share_topics(self, topics: List[str]) -> None:
        """Other code of this node is about to subscribe to ``topics`` with Subscribers (a
        dynamic_reconfigure client): the taps there move to Subscribers it can share."""
        with self.lock:
            taps = [self.taps[t] for t in topics if t in self.taps]
        for tap in taps:
            tap.use_subscriber()

    def message_class(self, type_name: str) -> type:
        from minros.msgs import get_message_class

        return get_message_class(type_name)

    def tap(self, topic: str, type_name: Optional[str], key: Hashable,
            listener: Callable[[Incoming], None]) -> TopicTap:
        """Add ``listener`` to the tap of ``topic`` (created on first use)."""
        with self.lock:
            tap = self.taps.get(topic)
            if tap is None:
                data_class: type = minros.AnyMsg
                if type_name:
                    try:
                        cls = self.message_class(type_name)
                        data_class = raw_class(cls._type, cls._md5sum, cls._full_text)
                    except Exception:
                        data_class = minros.AnyMsg
                tap = TopicTap(self, topic, data_class)
                self.taps[topic] = tap
            tap.add(key, listener)
            return tap

    def untap(self, topic: str, key: Hashable) -> None:
        with self.lock:
            tap = self.taps.get(topic)
            if tap is None or not tap.remove(key):
                return
            del self.taps[topic]
        tap.close()

    def topic_stats(self) -> Dict[str, Dict[str, Any]]:
        """Per tapped topic: type, messages, bytes, rate (Hz), listeners."""
        with self.lock:
            taps = list(self.taps.values())
        return {t.topic: {"type": t.type, "messages": t.count, "bytes": t.bytes,
                          "rate": t.rate(), "listeners": len(t.listeners)} for t in taps}

    # -- publishers ------------------------------------------------------------------------

    def acquire_publisher(self, client: Hashable, topic: str, data_class: type,
                          latch: bool = False, queue_size: int = 100) -> SharedPublisher:
        """The shared publisher of ``topic`` for ``client``; TypeError when the topic is already
        published here with another type."""
        with self.lock:
            pub = self.publishers.get(topic)
            if pub is not None and pub.data_class._md5sum != data_class._md5sum:
                raise TypeError(f"Tried to register topic {topic} with type {data_class._type} "
                                f"but it is already established with type {pub.data_class._type}")
            if pub is None:
                pub = SharedPublisher(topic, data_class, latch, queue_size)
                self.publishers[topic] = pub
            if pub.timer is not None:
                pub.timer.cancel()
                pub.timer = None
            pub.clients.add(client)
        self.poke()
        return pub

    def release_publisher(self, client: Hashable, topic: str, delay: Optional[float] = None) -> None:
        with self.lock:
            pub = self.publishers.get(topic)
            if pub is None:
                return
            pub.clients.discard(client)
            if pub.clients or pub.timer is not None:
                return
            delay = self.options.unregister_timeout if delay is None else delay
            pub.timer = threading.Timer(delay, self._unregister_publisher, args=(topic, pub))
            pub.timer.daemon = True
            pub.timer.name = "minros-web-unregister"
            pub.timer.start()

    def _unregister_publisher(self, topic: str, pub: SharedPublisher) -> None:
        with self.lock:
            if self.publishers.get(topic) is not pub or pub.clients:
                return
            del self.publishers[topic]
        pub.publisher.unregister()

    # -- services --------------------------------------------------------------------------

    def call_service(self, service: str, request: Any, service_class: type) -> Any:
        proxy = minros.ServiceProxy(service, service_class)
        try:
            return proxy.call(request)
        finally:
            proxy.close()

    def call_service_raw(self, service: str, type_name: str, md5sum: str, payload: bytes) -> bytes:
        cls = raw_service_class(type_name, md5sum)
        response = self.call_service(service, cls._request_class(bytes(payload)), cls)
        return bytes(response._buff)

    # -- parameters ------------------------------------------------------------------------

    def get_param(self, name: str, *default: Any) -> Any:
        """minros.get_param: KeyError when unset and no default is given."""
        return minros.get_param(name, *default)

    def set_param(self, name: str, value: Any) -> None:
        minros.set_param(name, value)
        # the master sends no paramUpdate to the node that set the value
        self._on_param_update(minros.resolve_name(name), value)

    def has_param(self, name: str) -> bool:
        return minros.has_param(name)

    def delete_param(self, name: str) -> None:
        minros.delete_param(name)

    def search_param(self, name: str) -> Optional[str]:
        return minros.search_param(name)

    def get_param_names(self) -> List[str]:
        return minros.get_param_names()

    def add_param_listener(self, key: Hashable,
                           listener: Callable[[Dict[str, Any], List[str]], None]) -> None:
        """``listener(changed leaves, removed leaves)`` after each change of the parameters."""
        with self.lock:
            self.param_listeners[key] = listener
            subscribed = self._params_subscribed
        if not subscribed:
            try:
                self._subscribe_params()
            except Exception as exc:  # the master is away: the graph thread tries again
                minros.logdebug(f"[web] subscribeParam failed: {exc}")
                self.poke()

    def param_tree(self) -> Any:
        """The whole parameter tree, read from the master now."""
        return self._call("getParam", "/")

    def remove_param_listener(self, key: Hashable) -> None:
        with self.lock:
            self.param_listeners.pop(key, None)

    def _subscribe_params(self) -> None:
        """subscribeParam('/') once: the master then pushes every change (paramUpdate), except
        the ones this node makes, which :meth:`set_param` applies itself."""
        from minros.node import default_node

        node = default_node()
        with self.lock:
            if self._params_subscribed:
                return
            if not self._param_handler_added:
                node.add_param_update_handler(self._on_param_update)
                self._param_handler_added = True
        tree = node.subscribe_param("/")
        flat: Dict[str, Any] = {}
        flatten_params("", tree, flat)
        with self.lock:
            self._params = flat
            self._params_subscribed = True

    def _on_param_update(self, key: str, value: Any) -> bool:
        with self.lock:
            if self._params is None:
                return True
            changed, removed = apply_param_update(self._params, key, value)
            listeners = list(self.param_listeners.values()) if changed or removed else []
        for listener in listeners:
            try:
                listener(changed, removed)
            except Exception as exc:
                minros.logerr(f"[web] parameter listener failed: {exc}")
        return True

    # -- time ------------------------------------------------------------------------------

    def now(self) -> Any:
        return minros.get_rostime()

    def now_ns(self) -> int:
        if self.use_sim_time:
            return minros.get_rostime().to_nsec()
        return time.time_ns()


_MISSING = object()


def apply_param_update(flat: Dict[str, Any], key: str, value: Any
                       ) -> Tuple[Dict[str, Any], List[str]]:
    """Apply a paramUpdate (``key`` set to ``value``; ``{}`` when deleted) to the flat leaf
    table ``flat`` in place; the leaves that changed and the ones that are gone."""
    key = key.rstrip("/") or "/"
    prefix = "/" if key == "/" else key + "/"
    new: Dict[str, Any] = {}
    if not (isinstance(value, dict) and not value):
        flatten_params("" if key == "/" else key, value, new)
    old = {k: v for k, v in flat.items() if k == key or k.startswith(prefix)}
    parts = key.split("/")
    for depth in range(1, len(parts) - 1):  # a value that was where a namespace now is
        ancestor = "/".join(parts[:depth + 1])
        if ancestor in flat:
            old[ancestor] = flat[ancestor]
    changed = {k: v for k, v in new.items() if old.get(k, _MISSING) != v}
    removed = sorted(set(old) - set(new))
    for name in removed:
        del flat[name]
    flat.update(changed)
    return changed, removed


def flatten_params(prefix: str, value: Any, out: Dict[str, Any]) -> None:
    """The leaves of a parameter (sub)tree into ``out``: ``{"/ns/name": value}``; an empty
    namespace is a leaf of value ``{}``."""
    if isinstance(value, dict) and value:
        for key, item in value.items():
            flatten_params(f"{prefix}/{key}", item, out)
    else:
        out[prefix or "/"] = value
