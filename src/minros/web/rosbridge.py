"""One rosbridge v2 client: the ops of ROSBRIDGE_PROTOCOL.md with ROS 1 rosbridge 0.11's rules.

:class:`RosbridgeSession` reads a client's frames (``receive``) and answers through the client's
:class:`~minros.web.outbox.Outbox`; the ROS side is the shared
:class:`~minros.web.state.WebState`. Errors are reported as rosbridge's server logs them
(``"<op>: <reason>"``, same reasons) and, since a client cannot read the server's log, also
sent to the client as ``status`` messages (level ``error`` by default; ``set_level`` changes it).

Subscriptions are bounded per client: the latest ``queue_length`` messages (at least one, and at
most :data:`MAX_QUEUE_BYTES`) wait for a slow client, older ones are dropped. Service calls run
in worker threads, at most :data:`MAX_CALLS_IN_FLIGHT` per client.
"""

from __future__ import annotations

import itertools
import json
import sys
import threading
import time
from typing import Any, Callable, Dict, Iterable, Iterator, List, Optional, Tuple

import minros
from minros.web import cbor
from minros.web.convert import ConversionError, message_to_json, populate_message, request_values
from minros.web.outbox import Outbox
from minros.web.state import Incoming, WebState

LEVELS = {"info": 0, "warning": 1, "error": 2, "none": 3}
#: queue of a subscription whose client gave no queue_length (rosbridge sends those at once)
DEFAULT_QUEUE_LENGTH = 100
MAX_QUEUE_BYTES = 32 << 20
MAX_CALLS_IN_FLIGHT = 16
#: the largest publisher queue a client may ask for
MAX_PUBLISH_QUEUE = 1000
#: topics one client may subscribe to, topics and services it may advertise (2,000 is a
#: busy robot; each costs memory and a master registration)
MAX_PER_CLIENT = 10_000
#: ids of one client's subscriptions or advertisements of one topic
MAX_IDS_PER_TOPIC = 1_000
#: how long a ROS caller waits for a client that advertised a service
SERVICE_RESPONSE_TIMEOUT = 60.0
MAX_FRAGMENTED_MESSAGES = 64
#: bytes a received fragment is charged beyond its text (its string and table entry)
FRAGMENT_OVERHEAD = 100
FRAGMENT_TIMEOUT = 600.0


#: roughly how deep json.loads can nest (it counts against the interpreter's recursion limit)
MAX_JSON_DEPTH = sys.getrecursionlimit()


class OpError(Exception):
    """A client op that cannot be carried out; the text is what rosbridge would log."""


def _bounded(what: str, held: Any, key: Any, limit: int = 0) -> None:
    """OpError when a client adding ``key`` to ``held`` would hold more than ``limit`` (each
    costs the server memory, and a registration with the master)."""
    limit = limit or MAX_PER_CLIENT
    if key not in held and len(held) >= limit:
        raise OpError(f"this client has {len(held)} {what} already, the most one client may "
                      "have: remove some first")


def _queue_size(msg: Dict[str, Any]) -> int:
    """A client's publisher queue_size, kept to 1..MAX_PUBLISH_QUEUE: the queue holds the
    client's messages while a subscriber is slow, and 0 would make it unbounded in rospy."""
    value = msg.get("queue_size", 100)
    if type(value) is not int:
        raise OpError(f"Expected field queue_size to be an int. Invalid value: {str(value)[:80]}")
    return min(max(value, 1), MAX_PUBLISH_QUEUE)


def _check(msg: Dict[str, Any], fields: List[Tuple[bool, str, tuple]]) -> None:
    """rosbridge's basic_type_check (same texts)."""
    for mandatory, name, types in fields:
        if mandatory and name not in msg:
            raise OpError(f"Expected a {name} field but none was found.")
        if name in msg and not isinstance(msg[name], types):
            names = tuple(t.__name__ for t in types)
            raise OpError(f"Expected field {name} to be one of {names}. Invalid value: "
                          f"{str(msg[name])[:200]}")


class _Subscription:
    """One client's subscription to one topic: several ids may share it (rosbridge's rules:
    the smallest throttle_rate and fragment_size win; the compression of the last one)."""

    def __init__(self) -> None:
        self.ids: Dict[Any, Dict[str, Any]] = {}
        self.name = ""  # the topic as the client named it (rosbridge echoes that name)

    def params(self) -> Dict[str, Any]:
        values = list(self.ids.values())
        frags = [v["fragment_size"] for v in values if v["fragment_size"] is not None]
        compressions = [v["compression"] for v in values]
        compression = "none"
        for candidate in ("png", "cbor", "cbor-raw"):
            if candidate in compressions:
                compression = candidate
        return {"throttle_rate": min(v["throttle_rate"] for v in values),
                "queue_length": min(v["queue_length"] for v in values),
                "fragment_size": min(frags) if frags else None,
                "compression": compression}


class RosbridgeSession:
    def __init__(self, client_id: str, state: WebState, outbox: Outbox,
                 close_client: Callable[[str], None], rosapi: Any = None,
                 run_async: Optional[Callable[[Callable[[], None]], None]] = None) -> None:
        self.client_id = client_id
        self.state = state
        self.outbox = outbox
        self.close_client = close_client
        self.rosapi = rosapi
        self.level = LEVELS["error"]
        self.subscriptions: Dict[str, _Subscription] = {}
        self.advertised: Dict[str, set] = {}  # topic -> advertisement ids
        self.published: set = set()
        self.services: Dict[str, Tuple[Any, type]] = {}  # advertised here: name -> (Service, class)
        self.pending: Dict[str, Tuple[threading.Event, list]] = {}
        self.fragments: Dict[Any, Dict[str, Any]] = {}
        self._request_ids = itertools.count(1)
        self._calls = threading.BoundedSemaphore(MAX_CALLS_IN_FLIGHT)
        self._run_async = run_async or self._thread
        self._closed = False
        self.lock = threading.Lock()
        self.ops: Dict[str, Callable[[Dict[str, Any]], None]] = {
            "advertise": self.advertise, "unadvertise": self.unadvertise,
            "publish": self.publish, "subscribe": self.subscribe,
            "unsubscribe": self.unsubscribe, "call_service": self.call_service,
            "advertise_service": self.advertise_service,
            "unadvertise_service": self.unadvertise_service,
            "service_response": self.service_response, "fragment": self.fragment,
            "set_level": self.set_level, "auth": lambda msg: None,
        }

    # -- plumbing --------------------------------------------------------------------------

    @staticmethod
    def _thread(fn: Callable[[], None]) -> None:
        threading.Thread(target=fn, name="minros-web-call", daemon=True).start()

    def send(self, obj: Dict[str, Any]) -> None:
        text = json.dumps(obj)
        if not self.outbox.put_control(text, len(text)):
            self.close_client("the client does not read its messages")

    def log(self, level: str, text: str, op_id: Any = None) -> None:
        """Log as rosbridge does and tell the client with a status message."""
        line = f"[Client {self.client_id}] " + (f"[id: {op_id}] " if op_id is not None else "") + text
        {"error": minros.logerr, "warning": minros.logwarn}.get(level, minros.logdebug)(line)
        if LEVELS.get(level, 0) >= self.level and self.level < LEVELS["none"]:
            status: Dict[str, Any] = {"op": "status", "level": level, "msg": text}
            if op_id is not None:
                status["id"] = op_id
            self.send(status)

    # -- input -----------------------------------------------------------------------------

    def receive(self, data: Any) -> None:
        """Handle one WebSocket message from the client."""
        if isinstance(data, (bytes, bytearray, memoryview)):
            try:
                data = bytes(data).decode("utf-8")
            except UnicodeDecodeError:
                self.log("error", "Received a binary message that is not UTF-8 JSON; send "
                                  "rosbridge ops as JSON text")
                return
        try:
            msg = json.loads(data)
        except ValueError as exc:
            excerpt = data[:80] + ("..." if len(data) > 80 else "")
            self.log("error", f"Received a message that is not valid JSON ({exc}): {excerpt}; "
                              "send one JSON object per message")
            return
        except RecursionError:  # json's C parser counts its depth against the recursion limit
            self.log("error", "Received JSON nested too deeply to read (more than "
                              f"{MAX_JSON_DEPTH} levels); rosbridge ops are a few levels deep")
            return
        if not isinstance(msg, dict):
            self.log("error", f"Received JSON that is not an object: {str(data)[:80]}")
            return
        op_id = msg.get("id")
        op = msg.get("op")
        if op is None:
            if "receiver" in msg:
                self.log("error", "Received a rosbridge v1.0 message.  Please refer to rosbridge.org "
                                  "for the correct format of rosbridge v2.0 messages.  Original "
                                  f"message was: {data[:200]}")
            else:
                self.log("error", "Received a message without an op.  All messages require 'op' "
                                  f"field with value one of: {list(self.ops)}.  Original message "
                                  f"was: {data[:200]}", op_id)
            return
        handler = self.ops.get(op) if isinstance(op, str) else None
        if handler is None:
            self.log("error", f"Unknown operation: {op}.  Allowed operations: {list(self.ops)}", op_id)
            return
        try:
            handler(msg)
        except (OpError, ConversionError, TypeError, LookupError, ValueError) as exc:
            self.log("error", f"{op}: {exc}", op_id)
        except Exception as exc:
            self.log("error", f"{op}: {type(exc).__name__}: {exc}", op_id)

    # -- topics ----------------------------------------------------------------------------

    def _class(self, type_name: str) -> type:
        try:
            return self.state.message_class(type_name)
        except Exception as exc:
            raise OpError(f"Unable to load the message type {type_name}: {exc}") from None

    def _established_class(self, topic: str, type_name: Optional[str]) -> type:
        known = self.state.topic_type(topic)
        if type_name is None:
            if known is None:
                raise OpError(f"Cannot infer topic type for topic {topic} as it is not yet advertised")
            type_name = known
        cls = self._class(type_name)
        if known is not None and known != cls._type:
            raise OpError(f"Tried to register topic {topic} with type {cls._type} but it is "
                          f"already established with type {known}")
        return cls

    def _allowed(self, topic: str) -> None:
        if not self.state.topic_allowed(topic):
            raise OpError(f"topic {topic} is not in the server's topics_glob")

    def advertise(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "topic", (str,)), (True, "type", (str,))])
        topic = minros.resolve_name(msg["topic"])
        self._allowed(topic)
        cls = self._established_class(topic, msg["type"])
        ids = self.advertised.get(topic, set())
        _bounded("advertised topics", self.advertised, topic)
        _bounded(f"advertisements of {topic}", ids, msg.get("id"), MAX_IDS_PER_TOPIC)
        self.state.acquire_publisher(self, topic, cls, latch=bool(msg.get("latch", False)),
                                     queue_size=_queue_size(msg))
        self.advertised.setdefault(topic, set()).add(msg.get("id"))

    def unadvertise(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "topic", (str,))])
        topic = minros.resolve_name(msg["topic"])
        ids = self.advertised.get(topic)
        if ids is None:
            return
        if msg.get("id") is None:
            ids.clear()
        else:
            ids.discard(msg["id"])
        if not ids:
            del self.advertised[topic]
            if topic not in self.published:
                self.state.release_publisher(self, topic)

    def publish(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "topic", (str,))])
        topic = minros.resolve_name(msg["topic"])
        self._allowed(topic)
        pub = self.state.publishers.get(topic)
        if pub is None or self not in pub.clients:
            cls = self._established_class(topic, None) if pub is None else pub.data_class
            pub = self.state.acquire_publisher(self, topic, cls, latch=bool(msg.get("latch", False)),
                                               queue_size=_queue_size(msg))
            self.published.add(topic)
        cls = pub.data_class
        if issubclass(cls, minros.AnyMsg):  # set up by a Foxglove client: bytes publisher
            cls = self._class(cls._type)
        instance = cls()
        populate_message(msg.get("msg", {}), instance, self.state.now)
        pub.publish(instance)

    def subscribe(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "topic", (str,)), (False, "type", (str,)),
                     (False, "throttle_rate", (int,)), (False, "fragment_size", (int,)),
                     (False, "queue_length", (int,)), (False, "compression", (str,))])
        topic = minros.resolve_name(msg["topic"])
        self._allowed(topic)
        compression = msg.get("compression", "none")
        if compression not in ("none", "png", "cbor", "cbor-raw"):
            raise OpError(f"unknown compression {compression!r}: use none, cbor or cbor-raw")
        type_name = msg.get("type")
        if compression != "cbor-raw" or type_name is not None:
            cls = self._established_class(topic, type_name)
            type_name = cls._type
        if compression == "png":
            self.log("warning", "png compression is not supported; sending plain JSON", msg.get("id"))
        sub = self.subscriptions.get(topic)
        first = sub is None
        _bounded("subscribed topics", self.subscriptions, topic)
        if not first:
            _bounded(f"subscriptions to {topic}", sub.ids, msg.get("id"), MAX_IDS_PER_TOPIC)
        if first:
            sub = self.subscriptions[topic] = _Subscription()
        sub.ids[msg.get("id")] = {
            "throttle_rate": max(0, msg.get("throttle_rate", 0)),
            "queue_length": max(0, msg.get("queue_length", 0)),
            "fragment_size": msg.get("fragment_size"), "compression": compression}
        sub.name = msg["topic"]
        self._configure(topic, sub)
        if first:
            self.state.tap(topic, type_name, self, self._listener(topic))
        self.log("info", f"Subscribed to {topic}")

    def _configure(self, topic: str, sub: _Subscription) -> None:
        params = sub.params()
        queue = params["queue_length"] or DEFAULT_QUEUE_LENGTH
        self.outbox.open_slot(("sub", topic), self._renderer(sub.name, params), maxlen=queue,
                              max_bytes=MAX_QUEUE_BYTES,
                              min_interval=params["throttle_rate"] / 1000.0)

    def _listener(self, topic: str) -> Callable[[Incoming], None]:
        key = ("sub", topic)
        put = self.outbox.put

        def listener(incoming: Incoming) -> None:
            put(key, incoming, incoming.size)
        return listener

    def _renderer(self, topic: str, params: Dict[str, Any]) -> Callable[[Incoming], Iterable[Any]]:
        compression = params["compression"]
        fragment_size = params["fragment_size"]
        if compression == "cbor":
            def render(incoming: Incoming) -> List[Any]:
                return [incoming.cached(("rosbridge-cbor", topic), lambda: cbor.dumps(
                    {"op": "publish", "topic": topic,
                     "msg": cbor.message_to_cbor_values(incoming.decoded())}))]
            return render
        if compression == "cbor-raw":
            def render_raw(incoming: Incoming) -> List[Any]:
                secs, nsecs = divmod(incoming.receive_ns, 1_000_000_000)
                return [incoming.cached(("rosbridge-cbor-raw", topic), lambda: cbor.dumps(
                    {"op": "publish", "topic": topic,
                     "msg": {"secs": secs, "nsecs": nsecs, "bytes": bytes(incoming.data)}}))]
            return render_raw

        def render_json(incoming: Incoming) -> Iterable[Any]:
            text = incoming.cached(("rosbridge-json", topic), lambda: json.dumps(
                {"op": "publish", "topic": topic, "msg": message_to_json(incoming.decoded())}))
            if fragment_size is not None and len(text) > fragment_size > 0:
                return fragment(text, fragment_size, next(_fragment_ids))
            return [text]
        return render_json

    def unsubscribe(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "topic", (str,))])
        topic = minros.resolve_name(msg["topic"])
        sub = self.subscriptions.get(topic)
        if sub is None:
            return
        if msg.get("id") is None:
            sub.ids.clear()
        else:
            sub.ids.pop(msg["id"], None)
        if sub.ids:
            self._configure(topic, sub)
        else:
            del self.subscriptions[topic]
            self.state.untap(topic, self)
            self.outbox.close_slot(("sub", topic))
        self.log("info", f"Unsubscribed from {topic}")

    # -- services --------------------------------------------------------------------------

    def call_service(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "service", (str,)), (False, "fragment_size", (int, type(None))),
                     (False, "compression", (str,))])
        service = msg["service"]
        op_id = msg.get("id")
        if op_id is None and "#" in service:  # the deprecated "/name#id" form
            op_id = service[service.find("#") + 1:]
        name = minros.resolve_name(service.split("#", 1)[0])
        if not self.state.service_allowed(name):
            raise OpError(f"service {name} is not in the server's services_glob")
        args = msg.get("args", [])
        if not self._calls.acquire(blocking=False):
            raise OpError(f"more than {MAX_CALLS_IN_FLIGHT} service calls in flight; wait for "
                          "their responses before calling again")

        def run() -> None:
            try:
                values = self._call(name, args)
                reply: Dict[str, Any] = {"op": "service_response", "service": service,
                                         "values": values, "result": True}
            except Exception as exc:
                # the failed service_response is the client's answer; the log line is ours
                minros.logerr(f"[Client {self.client_id}] [id: {op_id}] call_service "
                              f"{type(exc).__name__}: {exc}")
                reply = {"op": "service_response", "service": service, "values": str(exc),
                         "result": False}
            finally:
                self._calls.release()
            if op_id is not None:
                reply["id"] = op_id
            if not self._closed:
                self.send(reply)
        self._run_async(run)

    def _call(self, name: str, args: Any) -> Dict[str, Any]:
        from minros.msgs import get_service_class
        from minros.web.rosapi import SERVICES

        if self.rosapi is not None and name in SERVICES:
            srv = self.rosapi.service_class(name)
            request = srv._request_class()
            populate_message(request_values(args, request), request, self.state.now)
            return message_to_json(self.rosapi.handle(name, request))
        try:
            type_name = self.state.service_type(name)
        except LookupError:
            raise LookupError(f"Service {name} does not exist") from None
        if not type_name:
            raise LookupError(f"Service {name} does not exist")
        srv = get_service_class(type_name)
        request = srv._request_class()
        populate_message(request_values(args, request), request, self.state.now)
        return message_to_json(self.state.call_service(name, request, srv))

    def advertise_service(self, msg: Dict[str, Any]) -> None:
        from minros.msgs import get_service_class

        _check(msg, [(True, "service", (str,)), (True, "type", (str,))])
        name = msg["service"]
        if not self.state.service_allowed(name):
            raise OpError(f"service {name} is not in the server's services_glob")
        try:
            srv = get_service_class(msg["type"])
        except Exception as exc:
            raise OpError(f"Unable to load the service type {msg['type']}: {exc}") from None
        _bounded("advertised services", self.services, name)
        if name in self.services:
            self.log("warning", f"Duplicate service advertised. Overwriting {name}.")
            self.services.pop(name)[0].shutdown("Duplicate advertiser.")
        self.services[name] = (minros.Service(name, srv, self._service_handler(name)), srv)
        self.state.poke()
        self.log("info", f"Advertised service {name}.")

    def _service_handler(self, name: str) -> Callable[[Any], Any]:
        def handle(request: Any) -> Any:
            request_id = f"service_request:{name}:{next(self._request_ids)}"
            done = threading.Event()
            box: list = []
            with self.lock:
                self.pending[request_id] = (done, box)
            try:
                self.send({"op": "call_service", "id": request_id, "service": name,
                           "args": message_to_json(request)})
                if not done.wait(SERVICE_RESPONSE_TIMEOUT):
                    raise minros.ServiceException(
                        f"the rosbridge client serving {name} did not answer within "
                        f"{SERVICE_RESPONSE_TIMEOUT:.0f} s")
            finally:
                with self.lock:
                    self.pending.pop(request_id, None)
            if not box:
                raise minros.ServiceException(f"the rosbridge client serving {name} went away")
            if isinstance(box[0], Exception):
                raise minros.ServiceException(f"the rosbridge client serving {name} answered "
                                              f"with a response that does not fit: {box[0]}")
            return box[0]
        return handle

    def service_response(self, msg: Dict[str, Any]) -> None:
        """The answer of a client serving a ROS service. As rosbridge_suite's ROS 1 server, the
        ``values`` are the ROS caller's response whatever ``result`` says (its capability never
        reads ``result``; roslibjs and roslibpy send ``false`` when the handler returned false,
        with the values it filled). Values that do not fit fail the ROS call at once, naming
        why, where rosbridge leaves the caller waiting for good."""
        _check(msg, [(True, "service", (str,)), (True, "result", (bool,))])
        name = msg["service"]
        entry = self.services.get(name)
        if entry is None:
            raise OpError(f"Service {name} has not been advertised via rosbridge.")
        with self.lock:
            waiting = self.pending.get(msg.get("id"))
        if waiting is None:
            raise OpError(f"no call of {name} is waiting for a response with id {msg.get('id')!r}")
        done, box = waiting
        response = entry[1]._response_class()
        try:
            _check(msg, [(False, "values", (dict, type(None)))])
            populate_message(msg.get("values") or {}, response, self.state.now)
        except (OpError, ConversionError) as exc:
            box.append(exc)
            done.set()
            raise
        box.append(response)
        done.set()

    def unadvertise_service(self, msg: Dict[str, Any]) -> None:
        _check(msg, [(True, "service", (str,))])
        name = msg["service"]
        entry = self.services.pop(name, None)
        if entry is None:
            raise OpError(f"Service {name} has not been advertised via rosbridge, can't unadvertise.")
        entry[0].shutdown("Unadvertise request.")
        self.state.poke()
        self.log("info", f"Unadvertised service {name}.")

    # -- the rest --------------------------------------------------------------------------

    def set_level(self, msg: Dict[str, Any]) -> None:
        level = msg.get("level")
        if level in LEVELS:
            self.level = LEVELS[level]

    def fragment(self, msg: Dict[str, Any]) -> None:
        """Reassemble a message the client split (rosbridge's defragmentation), bounded."""
        _check(msg, [(True, "id", (str, int)), (True, "data", (str,)), (True, "num", (int,)),
                     (True, "total", (int,))])
        now = time.monotonic()
        for key in [k for k, v in self.fragments.items() if now - v["time"] > FRAGMENT_TIMEOUT]:
            del self.fragments[key]
        entry = self.fragments.get(msg["id"])
        if entry is None:
            if len(self.fragments) >= MAX_FRAGMENTED_MESSAGES:
                raise OpError(f"more than {MAX_FRAGMENTED_MESSAGES} fragmented messages in progress")
            entry = self.fragments[msg["id"]] = {"total": msg["total"], "parts": {}, "size": 0,
                                                 "time": now}
        total = entry["total"]
        if msg["total"] != total or not 0 <= msg["num"] < total or msg["num"] in entry["parts"]:
            raise OpError(f"error while trying to append fragment {msg['num']}")
        entry["parts"][msg["num"]] = msg["data"]
        # a part costs its text and its place in the table: 32 MB of 1-character parts would
        # otherwise hold 3 GB; and the messages in progress share the bound
        entry["size"] += len(msg["data"]) + FRAGMENT_OVERHEAD
        entry["time"] = now
        if sum(e["size"] for e in self.fragments.values()) > MAX_QUEUE_BYTES:
            del self.fragments[msg["id"]]
            raise OpError(f"fragmented message {msg['id']} does not fit: the fragments in progress "
                          f"would hold more than {MAX_QUEUE_BYTES} bytes (send larger fragments, "
                          "or fewer messages at once)")
        if len(entry["parts"]) == total:
            del self.fragments[msg["id"]]
            self.receive("".join(entry["parts"][i] for i in range(total)))

    def close(self) -> None:
        """The client is gone: drop its subscriptions, publishers and services."""
        self._closed = True
        for topic in list(self.subscriptions):
            self.state.untap(topic, self)
        self.subscriptions.clear()
        for topic in set(self.advertised) | self.published:
            self.state.release_publisher(self, topic)
        self.advertised.clear()
        self.published.clear()
        for service, _srv in self.services.values():
            service.shutdown("rosbridge client disconnected")
        if self.services:
            self.state.poke()
        self.services.clear()
        with self.lock:
            pending = list(self.pending.values())
        for done, _box in pending:
            done.set()


_fragment_ids = itertools.count()


def fragment(text: str, size: int, message_id: Any) -> Iterator[str]:
    """rosbridge's fragmentation of an outgoing JSON text into ``fragment`` ops, made one at a
    time as the writer sends them: the client picks ``fragment_size`` (1 byte would make a
    1080p image's 8 MB of JSON into 8 million texts at once)."""
    total = -(-len(text) // size)
    for n in range(total):
        yield json.dumps({"op": "fragment", "id": message_id, "data": text[n * size:(n + 1) * size],
                          "num": n, "total": total})
