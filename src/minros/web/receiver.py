"""The web node's subscriptions, without a thread each.

``minros web`` taps every topic its clients ask for, and one client may ask for thousands (a
Foxglove layout, a page of plots). A minros Subscriber, as rospy's, runs one receive thread per
publisher connection, which suits a node's few subscriptions and not this: 2,000 topics made the
server 2,017 threads and 238 MB (a thread and a 64 KB receive buffer per connection).

:class:`Receiver` holds the web node's subscriptions instead. One thread (``minros-web-receive``)
waits on every publisher connection with a selector and hands each message's bytes to the
topic's listener; a few workers (``minros-web-connect``) do what blocks, connecting as every
Subscriber does (:func:`minros.client.subscription.connect_publisher`: ``requestTopic`` with the
node's protocols, shared memory first between minros processes of one host, the chosen
protocol's ``connect`` and the subscriber's header exchange), then pass the transport to that
thread, which receives from it when its stream is readable. Each subscription is a
:class:`minros.node.Subscription` in the node's registry, so the master's ``publisherUpdate`` and
``getBusStats``/``getBusInfo`` reach it as they reach a Subscriber. A connection that fails or
ends is tried again after 0.5 s, doubling to 8 s, while the master still lists its publisher,
as Subscriber does; a publisher that refuses the connection (gone) or the topic is given up; a
protocol that cannot carry it (shared memory refused) is left out for that publisher, at once.

Listeners run in the receive thread, as a Subscriber's callbacks run in its: they must only
queue (every listener of ``minros web`` does).
"""

from __future__ import annotations

import errno
import heapq
import itertools
import selectors
import socket
import threading
import time
import traceback
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Dict, List, Optional, Tuple

import minros
from minros.client.subscription import GiveUp, connect_publisher
from minros.transport.base import FallBack, Transport, subscriber_header
from minros.wire import tcpros
from minros.wire.handshake import Rejected

#: the receive buffer of a connection: messages larger than this get a buffer of their own
#: as they arrive, so a small one keeps thousands of idle connections cheap
BUFF_SIZE = 4096
CONNECT_WORKERS = 4
#: receives of one connection per wake-up of the receive thread
READS_PER_WAKE = 4
FIRST_RETRY = 0.5
MAX_RETRY = 8.0

#: ``deliver(frame, header)``: one message's bytes and its connection's header
Deliver = Callable[[Any, Dict[str, str]], None]

_conn_ids = itertools.count(1)


class _Connection:
    """One publisher of one subscription: connected by a worker, then read by the receive
    thread. ``transport`` is the receive thread's once registered."""

    def __init__(self, sub: RawSubscription, pub_uri: str) -> None:
        self.id = next(_conn_ids)
        self.sub = sub
        self.pub_uri = pub_uri
        self.transport: Optional[Transport] = None
        self.connected = False
        self.done = False
        self.retry = FIRST_RETRY
        self.reported: set = set()
        #: protocols not offered to this publisher any more (they fell back)
        self.excluded: set = set()

    @property
    def header(self) -> Dict[str, str]:
        return self.transport.header if self.transport is not None else {}

    @property
    def protocol(self) -> str:
        return self.transport.protocol if self.transport is not None else ""

    @property
    def stat_bytes(self) -> int:
        return self.transport.stat_bytes if self.transport is not None else 0

    @property
    def stat_msgs(self) -> int:
        return self.transport.stat_msgs if self.transport is not None else 0

    def info(self) -> str:
        return self.transport.info() if self.transport is not None else ""

    # -- the worker's part -------------------------------------------------------------------

    def connect(self) -> Transport:
        """requestTopic, connect and exchange headers (blocking, bounded); the transport,
        its stream non-blocking (the receive thread reads it when it is readable)."""
        sub = self.sub
        fields = subscriber_header(sub.resolved_name, sub.data_class, sub.node.caller_id, True)
        try:
            transport = connect_publisher(sub.node, self.pub_uri, fields, excluded=self.excluded,
                                          buff_size=BUFF_SIZE, reuse_big=False, tcp_nodelay=True)
        except Rejected as exc:  # refused, or not the topic we asked for
            raise GiveUp(str(exc)) from None
        assert transport is not None
        try:
            transport.stream.setblocking(False)  # type: ignore[attr-defined]
        except BaseException:
            transport.close()
            raise
        return transport

    def failed(self, exc: BaseException) -> None:
        """One line per distinct failure (not one per retry); a publisher killed is quiet."""
        text = str(exc) or type(exc).__name__
        if isinstance(exc, (ConnectionResetError, ConnectionAbortedError, BrokenPipeError)):
            minros.logdebug(f"[web] publisher {self.pub_uri} of {self.sub.resolved_name} went "
                            f"away: {text}")
        elif not self.done and text not in self.reported and len(self.reported) < 16:
            self.reported.add(text)
            minros.logwarn(f"[{self.sub.resolved_name}] connection to publisher "
                           f"[{self.pub_uri}] failed: {text}")


class RawSubscription:
    """One topic the web node subscribes to: a :class:`minros.node.Subscription` whose
    connections the :class:`Receiver` serves; each message's bytes go to ``deliver``."""

    def __init__(self, receiver: Receiver, resolved_name: str, data_class: Any,
                 deliver: Deliver) -> None:
        self.receiver = receiver
        self.node = receiver.node
        self.resolved_name = resolved_name
        self.data_class = data_class
        self.type = data_class._type
        self.md5sum = data_class._md5sum
        self.deliver = deliver
        self.lock = threading.Lock()
        self.by_uri: Dict[str, _Connection] = {}
        self.publisher_uris: List[str] = []
        self.closed = False

    # -- the node's Subscription protocol ----------------------------------------------------

    def publisher_update(self, uris: List[str]) -> None:
        """The master's publishers of the topic now: connect to the new ones."""
        fresh = []
        with self.lock:
            if self.closed:
                return
            self.publisher_uris = [u for u in uris if isinstance(u, str)]
            for uri in self.publisher_uris:
                if uri not in self.by_uri:
                    conn = self.by_uri[uri] = _Connection(self, uri)
                    fresh.append(conn)
        for conn in fresh:
            self.receiver.connect_later(conn, 0.0)

    def get_stats(self) -> list:
        return [self.resolved_name, [[c.id, c.stat_bytes, c.stat_msgs, -1, c.connected]
                                     for c in list(self.by_uri.values())]]

    def get_stats_info(self) -> list:
        return [[c.id, c.pub_uri, "i", c.protocol, self.resolved_name, True, c.info()]
                for c in list(self.by_uri.values()) if c.connected]

    def get_num_connections(self) -> int:
        return sum(1 for c in list(self.by_uri.values()) if c.connected)

    def close(self) -> None:
        with self.lock:
            self.closed = True
            conns, self.by_uri = list(self.by_uri.values()), {}
        for conn in conns:
            conn.done = True
            self.receiver.drop_later(conn)

    # -- the receiver's ------------------------------------------------------------------------

    def wanted(self, conn: _Connection) -> bool:
        """Whether ``conn`` should be (re)connected: its publisher is still listed."""
        with self.lock:
            return (not self.closed and not conn.done and self.by_uri.get(conn.pub_uri) is conn
                    and conn.pub_uri in self.publisher_uris)

    def ended(self, conn: _Connection) -> None:
        """``conn`` is given up: forget it (a later publisherUpdate may name it again)."""
        with self.lock:
            if self.by_uri.get(conn.pub_uri) is conn:
                del self.by_uri[conn.pub_uri]


class Receiver:
    """Every subscription of the web node: one receive thread, a few connect workers."""

    def __init__(self, node: Any = None, workers: int = CONNECT_WORKERS) -> None:
        if node is None:
            from minros.node import default_node

            node = default_node()
        self.node = node
        self._selector = selectors.DefaultSelector()
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._selector.register(self._wake_r, selectors.EVENT_READ, None)
        self._lock = threading.Lock()
        self._posted: List[Callable[[], None]] = []
        self._timers: List[Tuple[float, int, Callable[[], None]]] = []
        self._seq = itertools.count()
        self._pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="minros-web-connect")
        self._stop = False
        self._thread = threading.Thread(target=self._loop, name="minros-web-receive", daemon=True)
        self._thread.start()

    # -- the API -------------------------------------------------------------------------------

    def subscribe(self, resolved_name: str, data_class: Any, deliver: Deliver) -> RawSubscription:
        """Subscribe the node to ``resolved_name`` (registered with the master now);
        ValueError when the node has a subscription there already (a Subscriber of its own,
        such as /clock on simulated time: the caller uses one too, sharing it)."""
        resolved_name = self.node.resolve_topic_name(resolved_name)
        if resolved_name in self.node.subscriptions:
            raise ValueError(f"the node already subscribes to {resolved_name}")
        sub = RawSubscription(self, resolved_name, data_class, deliver)
        self.node.add_subscription(sub)  # registerSubscriber, then publisher_update
        return sub

    def unsubscribe(self, sub: RawSubscription) -> None:
        sub.close()
        self.node.remove_subscription(sub)

    def close(self) -> None:
        self._stop = True
        self._wake()
        self._pool.shutdown(wait=False, cancel_futures=True)
        self._thread.join(timeout=5)

    # -- from any thread -----------------------------------------------------------------------

    def connect_later(self, conn: _Connection, delay: float) -> None:
        """Have a worker connect ``conn`` in ``delay`` seconds."""
        if delay <= 0:
            self._submit(conn)
        else:
            self._post(lambda: self._at(time.monotonic() + delay, lambda: self._submit(conn)))

    def drop_later(self, conn: _Connection) -> None:
        self._post(lambda: self._drop(conn))

    def _post(self, task: Callable[[], None]) -> None:
        with self._lock:
            self._posted.append(task)
        self._wake()

    def _wake(self) -> None:
        try:
            self._wake_w.send(b"\0")
        except (BlockingIOError, OSError):
            pass  # already awake (the pipe is full) or closing

    def _submit(self, conn: _Connection) -> None:
        if self._stop or not conn.sub.wanted(conn):
            conn.sub.ended(conn)
            return
        try:
            self._pool.submit(self._connect, conn)
        except RuntimeError:  # shutting down
            pass

    # -- a worker's ----------------------------------------------------------------------------

    def _connect(self, conn: _Connection) -> None:
        if self._stop or not conn.sub.wanted(conn):
            conn.sub.ended(conn)
            return
        try:
            transport = conn.connect()
        except (GiveUp, ValueError) as exc:
            minros.logdebug(f"[web] not connecting to {conn.pub_uri} for "
                            f"{conn.sub.resolved_name}: {exc}")
            conn.sub.ended(conn)
            return
        except FallBack as exc:  # the next protocol, at once
            self._fall_back(conn, exc)
            self.connect_later(conn, 0.0)
            return
        except (OSError, tcpros.HeaderError, tcpros.FrameError) as exc:
            if isinstance(exc, ConnectionRefusedError) or getattr(exc, "errno", None) == errno.ECONNREFUSED:
                minros.logdebug(f"[web] publisher {conn.pub_uri} is gone: {exc}")
                conn.sub.ended(conn)
                return
            conn.failed(exc)
            self._retry(conn)
            return
        except Exception as exc:  # an XML-RPC fault, a malformed answer: the publisher's bug
            conn.failed(exc)
            self._retry(conn)
            return
        self._post(lambda: self._register(conn, transport))

    @staticmethod
    def _fall_back(conn: _Connection, exc: FallBack) -> None:
        protocol = exc.protocol or conn.protocol
        conn.excluded.add(protocol)
        minros.logdebug(f"[web] {protocol} with {conn.pub_uri} for {conn.sub.resolved_name} "
                        f"failed: {exc}; falling back to the next protocol")

    def _retry(self, conn: _Connection) -> None:
        delay, conn.retry = conn.retry, min(conn.retry * 2, MAX_RETRY)
        self.connect_later(conn, delay)

    # -- the receive thread's ------------------------------------------------------------------

    def _at(self, due: float, task: Callable[[], None]) -> None:
        heapq.heappush(self._timers, (due, next(self._seq), task))

    def _register(self, conn: _Connection, transport: Transport) -> None:
        if self._stop or not conn.sub.wanted(conn):
            transport.close()
            conn.sub.ended(conn)
            return
        conn.transport = transport
        conn.connected = True
        conn.retry = FIRST_RETRY
        self._selector.register(transport.stream, selectors.EVENT_READ, conn)  # type: ignore[attr-defined]

    def _drop(self, conn: _Connection) -> None:
        """Close ``conn``'s transport (if it has one here) and stop reading it."""
        transport = conn.transport
        was = conn.connected
        conn.connected = False
        if transport is not None and was:
            try:
                self._selector.unregister(transport.stream)  # type: ignore[attr-defined]
            except (KeyError, ValueError):
                pass
        if transport is not None:
            transport.close()

    def _ended(self, conn: _Connection, exc: Optional[BaseException]) -> None:
        """The publisher closed the connection (or broke it): try again while it is listed
        (at once without a protocol that fell back)."""
        self._drop(conn)
        if isinstance(exc, FallBack):
            self._fall_back(conn, exc)
            if conn.sub.wanted(conn) and not self._stop:
                self.connect_later(conn, 0.0)
            else:
                conn.sub.ended(conn)
            return
        if exc is not None:
            conn.failed(exc)
        if conn.sub.wanted(conn) and not self._stop:
            self._retry(conn)
        else:
            conn.sub.ended(conn)

    def _read(self, conn: _Connection) -> None:
        """The stream is readable: what it brought (a few receives at most, so that one busy
        topic cannot hold the others; the last one also says an error the good frames before
        it waited on)."""
        transport = conn.transport
        for _ in range(READS_PER_WAKE):
            if transport is None or not conn.connected or conn.transport is not transport:
                return
            try:
                frames = transport.receive()
            except (BlockingIOError, InterruptedError):
                return
            except (OSError, tcpros.FrameError, FallBack) as exc:
                self._ended(conn, exc)
                return
            if frames is None:
                self._ended(conn, None)
                return
            deliver, header = conn.sub.deliver, transport.header
            for frame in frames:
                transport.stat_msgs += 1
                if conn.done:
                    return
                if frame.__class__ is memoryview:  # a slot of shared memory: it goes back next
                    frame = frame.tobytes()
                try:
                    deliver(frame, header)
                except Exception as exc:  # one listener's bug must not stop the others' topics
                    minros.logerr(f"[web] delivering {conn.sub.resolved_name} failed: {exc}")
            transport.release()  # the slots go back now, not when the publisher next sends

    @staticmethod
    def _run(task: Callable[..., None], *args: Any) -> None:
        """A task of the receive thread: a bug in one must not stop every topic."""
        try:
            task(*args)
        except Exception:
            minros.logerr(f"[web] receive thread: {traceback.format_exc()}")

    def _loop(self) -> None:
        select = self._selector.select
        while not self._stop:
            timeout = None
            if self._timers:
                timeout = max(0.0, self._timers[0][0] - time.monotonic())
            try:
                events = select(timeout)
            except OSError:  # a socket closed under us: the next round goes on without it
                events = []
            for key, _mask in events:
                if key.data is None:
                    try:
                        while self._wake_r.recv(4096):
                            pass
                    except (BlockingIOError, OSError):
                        pass
                else:
                    self._run(self._read, key.data)
            with self._lock:
                posted, self._posted = self._posted, []
            for task in posted:
                self._run(task)
            now = time.monotonic()
            while self._timers and self._timers[0][0] <= now:
                self._run(heapq.heappop(self._timers)[2])
        for key in list(self._selector.get_map().values()):
            if key.data is not None:
                self._drop(key.data)
        self._selector.close()
        self._wake_r.close()
        self._wake_w.close()
