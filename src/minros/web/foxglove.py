"""One Foxglove WebSocket client (``foxglove.websocket.v1``), as ROS 1's foxglove_bridge serves it.

Channels are the graph's topics (encoding ``ros1``, schema = the type's full definition); a
subscription forwards the TCPROS bytes of each message unchanged. Clients may publish (their
channels become publishers of the web node, their bytes are checked against the type before
they are forwarded), call services (raw request bytes in, raw response bytes out), read, set and
follow parameters (Lichtblick's 3D panel draws the URDF of ``/robot_description``) and follow
the connection graph, and fetch assets (``fetchAsset``: the meshes and textures that URDF
names, by ``package://`` or ``file://`` URL, under foxglove_bridge's allow-list rules and only
from inside a ROS package, :mod:`minros.web.assets`); with ``use_sim_time`` the server sends
``/clock`` as Time messages. Errors are ``status`` messages (level 2) to that client only.
"""

from __future__ import annotations

import threading
from typing import Any, Callable, Dict, Iterator, List, Optional, Set, Tuple

import minros
from minros.msgs import reader_for
from minros.web import assets
from minros.web import foxglove_protocol as fp
from minros.web.outbox import Outbox
from minros.web.rosapi import Graph
from minros.web.state import Incoming, WebState, raw_class

CAPABILITIES = ["clientPublish", "parameters", "parametersSubscribe", "services",
                "connectionGraph", "assets"]
#: messages per subscription waiting for a slow client (foxglove_bridge's queue length)
QUEUE_LENGTH = 10
QUEUE_BYTES = 32 << 20
MAX_CALLS_IN_FLIGHT = 16
#: asset fetches one client may have in flight (resolved, queued or being sent)
MAX_FETCHES_IN_FLIGHT = 8
#: subscriptions and advertised channels one client may hold (each costs memory; a channel
#: a publisher and a master registration)
MAX_PER_CLIENT = 10_000


def _graph_maps(graph: Graph) -> Tuple[Dict[str, Set[str]], ...]:
    return ({t: set(n) for t, n in graph.publishers.items()},
            {t: set(n) for t, n in graph.subscribers.items()},
            {s: set(n) for s, n in graph.services.items()})


class FoxgloveSession:
    def __init__(self, client_id: str, state: WebState, outbox: Outbox,
                 close_client: Callable[[str], None], server_name: str = "minros web",
                 run_async: Optional[Callable[[Callable[[], None]], None]] = None,
                 asset_patterns: Any = assets.DEFAULT_PATTERNS,
                 asset_budget: Optional[assets.Budget] = None, peer: str = "",
                 asset_timeout: float = 10.0) -> None:
        self.client_id = client_id
        self.state = state
        self.outbox = outbox
        self.close_client = close_client
        self.server_name = server_name
        self.run_async = run_async or self._thread
        self.lock = threading.RLock()
        self.channels: Dict[int, Tuple[str, str]] = {}  # advertised: id -> (topic, type)
        self.services: Dict[int, Tuple[str, str]] = {}  # advertised: id -> (name, type)
        self.subscriptions: Dict[int, int] = {}  # subscription id -> channel id
        self.client_channels: Dict[int, Tuple[str, type]] = {}  # client channel id -> (topic, class)
        self.param_names: Optional[Set[str]] = None  # None: no parameter subscription
        self.graph_subscribed = False
        self._graph_sent: Tuple[Dict[str, Set[str]], ...] = ({}, {}, {})
        self._calls = threading.BoundedSemaphore(MAX_CALLS_IN_FLIGHT)
        self._fetches = threading.BoundedSemaphore(MAX_FETCHES_IN_FLIGHT)
        self.asset_patterns = asset_patterns
        #: the server's budget of file bytes in memory, this client's address, and how long
        #: a chunk may wait for room
        self.asset_budget = asset_budget or assets.Budget()
        self.peer = peer or client_id.rpartition(":")[0]
        self.asset_timeout = asset_timeout
        self._closed = False

    @staticmethod
    def _thread(fn: Callable[[], None]) -> None:
        threading.Thread(target=fn, name="minros-web-foxglove-call", daemon=True).start()

    # -- output ----------------------------------------------------------------------------

    def send(self, obj: Dict[str, Any]) -> None:
        text = fp.dumps(obj)
        if not self.outbox.put_control(text, len(text)):
            self.close_client("the client does not read its messages")

    def send_binary(self, data: bytes) -> None:
        if not self.outbox.put_control(data, len(data)):
            self.close_client("the client does not read its messages")

    def error(self, text: str) -> None:
        minros.logwarn(f"[web] Foxglove client {self.client_id}: {text}")
        self.send(fp.status(fp.ERROR, text))

    # -- lifecycle -------------------------------------------------------------------------

    def start(self) -> None:
        capabilities = list(CAPABILITIES)
        if self.state.use_sim_time:
            capabilities.append("time")
        session_id = str(minros.get_param("/run_id", "") or int(self.state.started))
        self.send(fp.server_info(self.server_name, capabilities, session_id,
                                 {"ROS_DISTRO": "noetic"}))
        self.state.add_graph_listener(self, self.on_graph)
        self.on_graph(self.state.graph)
        if self.state.use_sim_time:
            self.outbox.open_slot("time", lambda ns: [fp.time_frame(ns)], maxlen=1)
            self.state.tap("/clock", "rosgraph_msgs/Clock", (self, "clock"), self._on_clock)
        self.state.poke()

    def _on_clock(self, incoming: Incoming) -> None:
        clock = incoming.decoded().clock
        self.outbox.put("time", clock.secs * 1_000_000_000 + clock.nsecs, 9)

    def close(self) -> None:
        self._closed = True
        self.state.remove_graph_listener(self)
        self.state.remove_param_listener(self)
        with self.lock:
            subscribed = dict(self.subscriptions)
            self.subscriptions.clear()
            topics = {topic for topic, _cls in self.client_channels.values()}
            self.client_channels.clear()
        for sub_id, channel_id in subscribed.items():
            self.state.untap(self.channels.get(channel_id, ("", ""))[0], (self, sub_id))
        if self.state.use_sim_time:
            self.state.untap("/clock", (self, "clock"))
        for topic in topics:
            self.state.release_publisher(self, topic, delay=0.0)

    # -- the graph -------------------------------------------------------------------------

    def on_graph(self, graph: Graph) -> None:
        """Advertise new channels and services, withdraw gone ones, update the graph view."""
        with self.lock:
            if self._closed:
                return
            wanted: Dict[int, Tuple[str, str]] = {}
            for topic, type_name in graph.topic_types.items():
                if type_name and type_name != "*" and self.state.topic_allowed(topic):
                    wanted[self.state.channel_id(topic, type_name)] = (topic, type_name)
            gone = [cid for cid in self.channels if cid not in wanted]
            new = [(cid, tt) for cid, tt in wanted.items() if cid not in self.channels]
            for cid in gone:
                sub_ids = [s for s, c in self.subscriptions.items() if c == cid]
                for sub_id in sub_ids:
                    self._unsubscribe(sub_id)
                del self.channels[cid]
            if gone:
                self.send(fp.unadvertise(gone))
            if new:
                channels = []
                for cid, (topic, type_name) in new:
                    self.channels[cid] = (topic, type_name)
                    channels.append(fp.channel(cid, topic, type_name, self._definition(type_name)))
                self.send(fp.advertise(channels))
            self._update_services(graph)
            if self.graph_subscribed:
                self._send_graph(graph)

    def _definition(self, type_name: str) -> str:
        try:
            return self.state.message_class(type_name)._full_text
        except Exception:
            return ""  # foxglove_bridge also advertises types it cannot describe, schema empty

    def _update_services(self, graph: Graph) -> None:
        wanted: Dict[int, Tuple[str, str, Any]] = {}
        for name in graph.services:
            if not self.state.service_allowed(name):
                continue
            try:
                type_name = self.state.service_type(name)
                from minros.msgs import get_service_class

                srv = get_service_class(type_name)
            except Exception:
                continue  # gone meanwhile, or a type we cannot describe: try next time
            wanted[self.state.service_id(name, type_name)] = (name, type_name, srv)
        gone = [sid for sid in self.services if sid not in wanted]
        for sid in gone:
            del self.services[sid]
        if gone:
            self.send(fp.unadvertise_services(gone))
        new = []
        for sid, (name, type_name, srv) in wanted.items():
            if sid not in self.services:
                self.services[sid] = (name, type_name)
                new.append(fp.service(sid, name, type_name, srv._request_class._full_text,
                                      srv._response_class._full_text))
        if new:
            self.send(fp.advertise_services(new))

    def _send_graph(self, graph: Graph) -> None:
        maps = _graph_maps(graph)
        update = fp.connection_graph_update(self._graph_sent, maps)
        self._graph_sent = maps
        if update is not None:
            self.send(update)

    # -- input -----------------------------------------------------------------------------

    def receive(self, data: Any) -> None:
        try:
            if isinstance(data, str):
                self._text(fp.parse_text(data))
            else:
                self._binary(fp.parse_binary(data))
        except fp.ProtocolError as exc:
            self.error(str(exc))

    def _text(self, msg: Dict[str, Any]) -> None:
        op = msg["op"]
        handler = {
            "subscribe": self.subscribe, "unsubscribe": self.unsubscribe,
            "advertise": self.client_advertise, "unadvertise": self.client_unadvertise,
            "getParameters": self.get_parameters, "setParameters": self.set_parameters,
            "subscribeParameterUpdates": self.subscribe_parameters,
            "unsubscribeParameterUpdates": self.unsubscribe_parameters,
            "subscribeConnectionGraph": self.subscribe_graph,
            "unsubscribeConnectionGraph": self.unsubscribe_graph,
            "fetchAsset": self.fetch_asset,
        }.get(op)
        if handler is None:
            raise fp.ProtocolError(f'Unrecognized client opcode "{op}"')
        handler(msg)

    def _binary(self, frame: Any) -> None:
        if isinstance(frame, fp.ClientMessage):
            self.client_message(frame)
        else:
            self.service_call(frame)

    # -- subscriptions ---------------------------------------------------------------------

    def subscribe(self, msg: Dict[str, Any]) -> None:
        for entry in fp.dict_list(msg, "subscriptions"):
            sub_id, channel_id = entry.get("id"), entry.get("channelId")
            if type(sub_id) is not int or type(channel_id) is not int:
                self.error("subscribe: each subscription needs integer 'id' and 'channelId'")
                continue
            with self.lock:
                if sub_id in self.subscriptions:
                    self.error(f"Client subscription id {sub_id} was already used; ignoring subscription")
                    continue
                if len(self.subscriptions) >= MAX_PER_CLIENT:
                    self.error(f"this client has {MAX_PER_CLIENT} subscriptions already, the "
                               f"most one client may have; ignoring subscription {sub_id}")
                    continue
                channel = self.channels.get(channel_id)
                if channel is None:
                    self.error(f"Channel {channel_id} is not available; ignoring subscription")
                    continue
                self.subscriptions[sub_id] = channel_id
            topic, type_name = channel
            self.outbox.open_slot(("sub", sub_id), self._renderer(sub_id), maxlen=QUEUE_LENGTH,
                                  max_bytes=QUEUE_BYTES)
            put = self.outbox.put
            key = ("sub", sub_id)
            self.state.tap(topic, type_name, (self, sub_id),
                           lambda incoming, _put=put, _key=key: _put(_key, incoming, incoming.size))

    @staticmethod
    def _renderer(sub_id: int) -> Callable[[Incoming], List[bytes]]:
        def render(incoming: Incoming) -> List[bytes]:
            return [fp.message_data_head(sub_id, incoming.receive_ns) + incoming.data]
        return render

    def unsubscribe(self, msg: Dict[str, Any]) -> None:
        for sub_id in fp.int_list(msg, "subscriptionIds"):
            with self.lock:
                if sub_id not in self.subscriptions:
                    self.error(f"Client subscription id {sub_id} did not exist; ignoring unsubscription")
                    continue
                self._unsubscribe(sub_id)

    def _unsubscribe(self, sub_id: int) -> None:
        channel_id = self.subscriptions.pop(sub_id)
        self.outbox.close_slot(("sub", sub_id))
        self.state.untap(self.channels.get(channel_id, ("", ""))[0], (self, sub_id))

    # -- client publishing -----------------------------------------------------------------

    def client_advertise(self, msg: Dict[str, Any]) -> None:
        from minros.msgs import generate_dynamic

        for entry in fp.dict_list(msg, "channels"):
            channel_id, topic = entry.get("id"), entry.get("topic")
            type_name, encoding = entry.get("schemaName"), entry.get("encoding")
            if type(channel_id) is not int or not isinstance(topic, str) or not isinstance(type_name, str):
                self.error("advertise: each channel needs an integer 'id' and 'topic' and "
                           "'schemaName' strings")
                continue
            if encoding != fp.ENCODING:
                self.error(f"Unsupported encoding {encoding!r} for channel {channel_id}. Only "
                           f"'{fp.ENCODING}' encoding is supported at the moment.")
                continue
            if channel_id in self.client_channels:
                self.error(f"Client channel {channel_id} was already advertised")
                continue
            if len(self.client_channels) >= MAX_PER_CLIENT:
                self.error(f"this client advertised {MAX_PER_CLIENT} channels already, the most "
                           f"one client may; ignoring channel {channel_id}")
                continue
            if not self.state.topic_allowed(topic):
                self.error(f"topic {topic} is not in the server's topics_glob")
                continue
            try:
                cls = self.state.message_class(type_name)
            except Exception:
                schema = entry.get("schema")
                if not isinstance(schema, str) or not schema:
                    self.error(f"Failed to retrieve type information of data type '{type_name}'. "
                               f"Unable to advertise topic {topic}")
                    continue
                try:
                    cls = generate_dynamic(type_name, schema)[type_name]
                except Exception as exc:
                    self.error(f"advertise: the schema of '{type_name}' does not parse: {exc}")
                    continue
            raw = raw_class(cls._type, cls._md5sum, cls._full_text)
            try:
                self.state.acquire_publisher(self, topic, raw, queue_size=10)
            except TypeError as exc:
                self.error(str(exc))
                continue
            with self.lock:
                self.client_channels[channel_id] = (topic, cls)

    def client_unadvertise(self, msg: Dict[str, Any]) -> None:
        for channel_id in fp.int_list(msg, "channelIds"):
            with self.lock:
                entry = self.client_channels.pop(channel_id, None)
            if entry is None:
                self.error(f"Ignoring client unadvertisement for unknown channel {channel_id}")
                continue
            if entry[0] not in {t for t, _ in self.client_channels.values()}:
                self.state.release_publisher(self, entry[0], delay=0.0)

    def client_message(self, frame: fp.ClientMessage) -> None:
        entry = self.client_channels.get(frame.channel_id)
        if entry is None:
            self.error(f"Dropping client message for unknown channel {frame.channel_id}, "
                       f"client has {len(self.client_channels)} advertised topic(s)")
            return
        topic, cls = entry
        payload = bytes(frame.payload)
        try:  # a malformed payload stops here instead of breaking every subscriber
            # read from the bytes (every length checked against them before anything is built),
            # never cls() first: a schema the client chose ("float64[100000000] a") would make
            # the default instance take 800 MB before a 13-byte message was found short
            msg = reader_for(cls)(payload)
        except Exception as exc:
            self.error(f"Dropping a message on {topic}: the payload is not a valid "
                       f"{cls._type}: {exc}")
            return
        pub = self.state.publishers.get(topic)
        if pub is None:
            self.error(f"Dropping client message: {topic} is no longer advertised")
            return
        # bytes as they came, unless a rosbridge client set the publisher up with the real class
        pub.publish(pub.data_class(payload) if issubclass(pub.data_class, minros.AnyMsg) else msg)

    # -- services --------------------------------------------------------------------------

    def service_call(self, request: fp.ServiceCallRequest) -> None:
        entry = self.services.get(request.service_id)
        if entry is None:
            self.send(fp.service_call_failure(request.service_id, request.call_id,
                                              f"Service with id {request.service_id} does not exist"))
            return
        if request.encoding != fp.ENCODING:
            self.send(fp.service_call_failure(request.service_id, request.call_id,
                                              f"Unsupported encoding {request.encoding!r}: use "
                                              f"'{fp.ENCODING}'"))
            return
        if not self._calls.acquire(blocking=False):
            self.send(fp.service_call_failure(request.service_id, request.call_id,
                                              f"more than {MAX_CALLS_IN_FLIGHT} calls in flight"))
            return
        name, type_name = entry
        payload = bytes(request.payload)

        def run() -> None:
            try:
                from minros.msgs import get_service_class

                srv = get_service_class(type_name)
                data = self.state.call_service_raw(name, type_name, srv._md5sum, payload)
                reply: Any = fp.service_call_response(request.service_id, request.call_id,
                                                      request.encoding, data)
            except Exception as exc:
                reply = fp.service_call_failure(request.service_id, request.call_id,
                                                f"Failed to call service {name}({type_name}): {exc}")
            finally:
                self._calls.release()
            if self._closed:
                return
            if isinstance(reply, bytes):
                self.send_binary(reply)
            else:
                self.send(reply)
        self.run_async(run)

    # -- assets ----------------------------------------------------------------------------

    def fetch_asset(self, msg: Dict[str, Any]) -> None:
        """foxglove_bridge's fetchAsset: the file's bytes, or an error naming the URI (and,
        unlike foxglove_bridge, why); resolved in a worker thread, read as it is sent."""
        uri, request_id = msg.get("uri"), msg.get("requestId")
        if not isinstance(uri, str) or type(request_id) is not int or not 0 <= request_id < 1 << 32:
            self.error("fetchAsset needs a string 'uri' and an integer 'requestId' (0 to 2^32-1)")
            return
        if not self._fetches.acquire(blocking=False):
            self.send_binary(fp.fetch_asset_response(
                request_id, error=f"Failed to retrieve asset {uri}: more than "
                                  f"{MAX_FETCHES_IN_FLIGHT} fetches in flight"))
            return

        def run() -> None:
            try:
                path = assets.resolve(uri, self.asset_patterns)
                stream, size = assets.open_file(path, uri)
            except assets.AssetError as exc:
                self._fetches.release()
                self._asset_failed(request_id, uri, exc)
                return
            if self._closed:
                stream.close()
                self._fetches.release()
                return
            # one message, sent as fragments while the file is read (assets.chunks): the
            # reply holds one chunk of the budget at a time, never the whole file
            reply = assets.Fragments(lambda: self._asset_fragments(request_id, stream, size))
            if not self.outbox.put_control(reply, assets.CHUNK_BYTES):
                stream.close()
                self._fetches.release()
                self.close_client("the client does not read its messages")
        self.run_async(run)

    def _asset_fragments(self, request_id: int, stream: Any, size: int) -> Iterator[bytes]:
        try:
            with stream:
                yield fp.fetch_asset_response(request_id, b"")
                yield from assets.chunks(stream, size, self.asset_budget, self.peer,
                                         self.asset_timeout)
        finally:
            self._fetches.release()

    def _asset_failed(self, request_id: int, uri: str, exc: assets.AssetError) -> None:
        minros.logwarn(f"[web] Foxglove client {self.client_id}: Failed to retrieve "
                       f"asset '{uri[:300]}': {exc}")
        if not self._closed:
            self.send_binary(fp.fetch_asset_response(
                request_id, error=f"Failed to retrieve asset {uri}: {exc}"))

    # -- parameters ------------------------------------------------------------------------

    def _param_allowed(self, name: str) -> bool:
        import fnmatch

        globs = self.state.options.params_glob
        return not globs or any(fnmatch.fnmatch(name, g) for g in globs)

    def _values(self, names: List[str]) -> List[Tuple[str, Any]]:
        out = []
        for name in names:
            if not self._param_allowed(name):
                continue
            try:
                out.append((name, self.state.get_param(name)))
            except KeyError:  # not set (or deleted meanwhile)
                continue
        return out

    def get_parameters(self, msg: Dict[str, Any]) -> None:
        names = fp.str_list(msg, "parameterNames", [])
        request_id = msg.get("id") if isinstance(msg.get("id"), str) else None
        if not names:
            names = self.state.get_param_names()
        self.send(fp.parameter_values(self._values(names), request_id))

    def set_parameters(self, msg: Dict[str, Any]) -> None:
        entries = fp.dict_list(msg, "parameters")
        names = []
        for entry in entries:
            name, value, delete = fp.parameter_from_client(entry)
            names.append(name)
            if not self._param_allowed(name):
                self.error(f"Parameter '{name}' is not on the allowlist")
                continue
            try:
                if delete:
                    if self.state.has_param(name):
                        self.state.delete_param(name)
                else:
                    self.state.set_param(name, value)
            except Exception as exc:
                self.error(f"Failed to set parameter '{name}': {exc}")
        if isinstance(msg.get("id"), str):
            self.send(fp.parameter_values(self._values(names), msg["id"]))

    def subscribe_parameters(self, msg: Dict[str, Any]) -> None:
        names = fp.str_list(msg, "parameterNames", [])
        with self.lock:
            if not names:
                names = self.state.get_param_names()
            self.param_names = (self.param_names or set()) | set(names)
        self.state.add_param_listener(self, self._on_params)

    def unsubscribe_parameters(self, msg: Dict[str, Any]) -> None:
        names = fp.str_list(msg, "parameterNames", [])
        with self.lock:
            if not names or self.param_names is None:
                self.param_names = None
            else:
                self.param_names -= set(names)
            if not self.param_names:
                self.param_names = None
                self.state.remove_param_listener(self)

    def _on_params(self, changed: Dict[str, Any], removed: List[str]) -> None:
        with self.lock:
            wanted = self.param_names or set()
            values = [(n, v) for n, v in changed.items() if n in wanted]
            gone = [n for n in removed if n in wanted]
        if values or gone:
            message = fp.parameter_values(values)
            message["parameters"] += [{"name": n} for n in gone]
            self.send(message)

    # -- connection graph ------------------------------------------------------------------

    def subscribe_graph(self, msg: Dict[str, Any]) -> None:
        with self.lock:
            self.graph_subscribed = True
            self._graph_sent = ({}, {}, {})
            self._send_graph(self.state.graph)

    def unsubscribe_graph(self, msg: Dict[str, Any]) -> None:
        with self.lock:
            self.graph_subscribed = False

