"""A subscription: every Subscriber handle of one topic in this process, and one connection to
each publisher the master names (rospy's _SubscriberImpl).

Each :class:`PublisherConnection` runs in a thread of its own: ``requestTopic`` on the
publisher's slave API with the protocols the node speaks (in its order), a transport from
the handler of the protocol the publisher chose, the connection-header exchange, then the
receive loop, which deserializes each frame and runs the callbacks itself (no hand-off, as in
rospy). A connection that fails is tried again while the master still lists its publisher,
backing off from 0.5 s to 8 s; a publisher that refuses the connection outright is left alone.
A protocol that cannot carry the connection after all (``FallBack``: shared memory refused or
broken) is said once and left out of the offers to that publisher from then on, at once.
A publisher of this very node that hands over its objects (``intraprocess``) is connected
without a requestTopic (``Node.local_transport``).
"""

from __future__ import annotations

import errno
import logging
import threading
import traceback
from typing import TYPE_CHECKING, Any, Callable, Collection, Dict, List, Tuple

from minros.client import log
from minros.transport.base import FallBack, Transport, subscriber_header
from minros.wire import tcpros
from minros.wire.handshake import Handshake, Rejected, Role
from minros.wire.rosapi import RemoteError
from minros.wire.slaveapi import SlaveClient

if TYPE_CHECKING:
    from minros.node import Node

__all__ = ["GiveUp", "PublisherConnection", "Subscription", "connect_publisher"]

_logger = logging.getLogger("minros.client.topics")

#: seconds to wait for a publisher's answer to requestTopic
REQUEST_TOPIC_TIMEOUT = 5.0
#: the first and the longest pause between two attempts to connect to a publisher
RETRY_FIRST, RETRY_MAX = 0.5, 8.0


class GiveUp(Exception):
    """The publisher will not serve us: do not try again."""


def _is_refused(exc: BaseException) -> bool:
    return isinstance(exc, ConnectionRefusedError) or getattr(exc, "errno", None) == errno.ECONNREFUSED


def connect_publisher(node: Node, pub_uri: str, fields: Dict[str, str], *,
                      excluded: Collection[str] = (), buff_size: int = tcpros.DEFAULT_BUFF_SIZE,
                      reuse_big: bool = False, tcp_nodelay: bool = False,
                      attach: Callable[[Transport], bool] | None = None) -> Transport | None:
    """How a subscriber of ``node`` connects to the publisher at ``pub_uri`` (every
    Subscriber's connection and ``minros web``'s taps): ``requestTopic`` offering the
    node's protocols in its order (less ``excluded``, TCPROS always), the chosen
    protocol's ``connect``, then the subscriber's header exchange with ``fields``.

    ``attach(transport)`` is told of the transport as soon as it exists (so that closing
    the connection meanwhile reaches it) and says whether to go on: when it says no, the
    transport is closed and None returned. Raises GiveUp (the publisher will not serve
    this topic), FallBack (its ``protocol`` cannot carry the connection: ask again
    without it), ValueError (an answer the handler cannot use), OSError, HeaderError or
    Rejected (the connection failed)."""
    protocols = node.protocols
    offers = [h for h in protocols[:-1] if h.protocol not in excluded] + protocols[-1:]
    try:
        with SlaveClient(pub_uri, node.caller_id, REQUEST_TOPIC_TIMEOUT) as publisher:
            answer = publisher.request_topic(fields["topic"], [h.offer() for h in offers])
    except RemoteError as exc:
        raise GiveUp(f"requestTopic: {exc}") from None
    handler = next((h for h in offers if h.protocol == answer[0]), None)
    if handler is None:
        raise GiveUp(f"publisher returned invalid protocol choice: {answer}")
    try:
        transport = handler.connect(answer, fields["topic"], buff_size, reuse_big,
                                    tcp_nodelay)
        if attach is not None and not attach(transport):
            transport.close()
            return None
        transport.negotiate(Handshake(Role.SUBSCRIBER, fields))
    except FallBack as exc:
        exc.protocol = handler.protocol
        raise
    return transport


class PublisherConnection:
    """Our connection to one publisher of a subscribed topic (runs in its own thread)."""

    def __init__(self, sub: Subscription, pub_uri: str) -> None:
        self.sub = sub
        self.pub_uri = pub_uri
        self.transport: Transport | None = None
        self.latch: Any = None
        self.done = False
        self.connected = False
        self.gen = 0
        self.reported: set = set()
        #: protocols not offered to this publisher any more (they fell back)
        self.excluded: set = set()
        self.thread = threading.Thread(target=self._run, daemon=True,
                                       name=f"minros-sub:{sub.resolved_name}")

    @property
    def id(self) -> int:
        return self.transport.id if self.transport is not None else 0

    @property
    def header(self) -> Dict[str, str]:
        return self.transport.header if self.transport is not None else {}

    @property
    def stat_bytes(self) -> int:
        return self.transport.stat_bytes if self.transport is not None else 0

    @property
    def stat_msgs(self) -> int:
        return self.transport.stat_msgs if self.transport is not None else 0

    @property
    def protocol(self) -> str:
        return self.transport.protocol if self.transport is not None else ""

    def info(self) -> str:
        return self.transport.info() if self.transport is not None else ""

    @property
    def endpoint_id(self) -> str:
        """rospy's name for the publisher's XML-RPC URI."""
        return self.pub_uri

    @property
    def callerid_pub(self) -> str:
        """The publisher's caller id, from its connection header ('unknown' before it)."""
        return self.header.get("callerid", "unknown")

    def close(self) -> None:
        self.done = True
        transport = self.transport
        if transport is not None:
            transport.close()

    # -- connection life ---------------------------------------------------------------------

    def _run(self) -> None:
        interval = RETRY_FIRST
        node = self.sub.node
        try:
            while not self.done and not node.is_shutdown():
                local = node.local_transport(self.sub.resolved_name, self.pub_uri,
                                             self.sub.data_class, self._fields())
                if local is not None:
                    self.transport = local
                    self.connected = True
                    try:
                        self._receive_loop()
                    finally:
                        self.connected = False
                        local.close()
                    return
                self.transport = None
                try:
                    if self._connect():
                        interval = RETRY_FIRST
                        self._receive_loop()
                except FallBack as exc:  # the next protocol, at once
                    self._fall_back(exc)
                    continue
                except (GiveUp, ValueError) as exc:  # will not serve us, or cannot be used
                    _logger.debug("not connecting to %s: %s", self.pub_uri, exc)
                    return
                except (OSError, tcpros.HeaderError, tcpros.FrameError, Rejected) as exc:
                    if self.transport is None and isinstance(exc, OSError):  # requestTopic
                        if _is_refused(exc):
                            _logger.debug("publisher %s is gone: %s", self.pub_uri, exc)
                            return
                        _logger.debug("requestTopic to %s failed: %s", self.pub_uri, exc)
                    else:
                        self._report(exc)
                finally:
                    self.connected = False
                    if self.transport is not None:
                        self.transport.close()
                if self.done or node.is_shutdown_requested():
                    return
                if self.pub_uri not in self.sub.publisher_uris:
                    return
                if node.wait_for_shutdown(interval):
                    return
                interval = min(interval * 2, RETRY_MAX)
        finally:
            self.sub.connection_ended(self)

    def _report(self, exc: BaseException) -> None:
        text = str(exc)
        if isinstance(exc, (ConnectionResetError, ConnectionAbortedError, BrokenPipeError)):
            # the publisher went away (killed): not worth a console line
            _logger.debug("publisher %s went away: %s", self.pub_uri, text)
        elif (not self.done and not self.sub.node.is_shutdown_requested()
                and text not in self.reported):
            # one line per distinct failure, not one per retry
            self.reported.add(text)
            log.logwarn(f"[{self.sub.resolved_name}] connection to publisher "
                        f"[{self.pub_uri}] failed: {text}")

    def _fall_back(self, exc: FallBack) -> None:
        """The protocol of ``exc`` cannot carry this connection: one line, and it is not
        offered to this publisher again."""
        protocol = exc.protocol or (self.transport.protocol if self.transport else "")
        self.excluded.add(protocol)
        if not self.done and not self.sub.node.is_shutdown_requested():
            log.logwarn(f"[{self.sub.resolved_name}] {protocol} with publisher "
                        f"[{self.pub_uri}] failed: {exc}; falling back to the next protocol")

    def _connect(self) -> bool:
        """Connect to the publisher (``connect_publisher``); False when closed meanwhile."""
        sub = self.sub
        transport = connect_publisher(
            sub.node, self.pub_uri, self._fields(), excluded=self.excluded,
            buff_size=sub.buff_size, reuse_big=not getattr(sub.data_class, "_keeps_buffer", True),
            tcp_nodelay=sub.tcp_nodelay, attach=self._attach)
        if transport is None:
            return False
        self.connected = True
        return True

    def _attach(self, transport: Transport) -> bool:
        self.transport = transport
        return not self.done  # closed while connecting: close() did not see the transport

    def _fields(self) -> Dict[str, str]:
        """Our connection header."""
        sub = self.sub
        return subscriber_header(sub.resolved_name, sub.data_class, sub.node.caller_id,
                                 sub.tcp_nodelay)

    def _receive_loop(self) -> None:
        sub = self.sub
        transport = self.transport
        assert transport is not None
        header = transport.header
        latching = header.get("latching", "0") == "1"
        read = transport.message_reader(sub.data_class)
        settle = transport.settle  # shared memory: the callbacks may keep a message
        deliver = sub.deliver if sub.statistics is None else sub.statistics.wrap(self, sub.deliver)
        receive = transport.receive
        while True:
            frames = receive()
            if not frames:
                if frames is None:  # the publisher closed the connection
                    return
                continue  # only part of a frame so far
            queue_size = sub.queue_size
            if queue_size is not None and len(frames) > queue_size:
                frames = frames[-queue_size:]  # older ones dropped, as in rospy
            transport.stat_msgs += len(frames)
            for frame in frames:
                try:
                    msg = read(frame)
                except Exception as exc:
                    log.logerr(f"[{sub.resolved_name}] error deserializing incoming message "
                               f"from [{self.pub_uri}]: {exc}")
                    continue
                try:
                    msg._connection_header = header
                except AttributeError:
                    pass
                if latching:
                    self.latch = msg
                if self.done:
                    return
                deliver(msg)
                if settle is not None:
                    settle(msg)
            if self.done:
                return


class Subscription:
    """Shared state of all Subscriber handles for one topic: one connection per publisher."""

    def __init__(self, node: Node, name: str, resolved_name: str, data_class: Any) -> None:
        self.node = node
        self.name = name
        self.resolved_name = resolved_name
        self.data_class = data_class
        self.type: str = data_class._type
        self.md5sum: str = data_class._md5sum
        self.callbacks: List[Tuple[Callable, Any]] = []
        self.queue_size: int | None = None
        self.buff_size = tcpros.DEFAULT_BUFF_SIZE
        self.tcp_nodelay = False
        #: publisher XML-RPC URI -> our connection to it
        self.by_uri: Dict[str, PublisherConnection] = {}
        self.publisher_uris: List[str] = []
        self.update_gen = 0
        self.lock = threading.RLock()
        self.ref_count = 0
        self.closed = False
        #: topic statistics (/enable_statistics), or None
        self.statistics: Any = None

    def publisher_update(self, uris: List[str]) -> None:
        """The master's current publisher list: connect to the new ones."""
        with self.lock:
            if self.closed:
                return
            self.publisher_uris = list(uris)
            self.update_gen += 1
            fresh = []
            for uri in uris:
                if uri not in self.by_uri:
                    conn = PublisherConnection(self, uri)
                    conn.gen = self.update_gen
                    self.by_uri[uri] = conn
                    fresh.append(conn)
        for conn in fresh:
            conn.thread.start()

    def connection_ended(self, conn: PublisherConnection) -> None:
        with self.lock:
            if self.by_uri.get(conn.pub_uri) is conn:
                del self.by_uri[conn.pub_uri]
            again = (not self.closed and not conn.done and conn.pub_uri in self.publisher_uris
                     and self.update_gen != conn.gen and not self.node.is_shutdown_requested())
        if again:  # the publisher was announced again while this connection was ending
            self.publisher_update(self.publisher_uris)

    def add_callback(self, cb: Callable, cb_args: Any) -> None:
        with self.lock:
            self.callbacks = self.callbacks + [(cb, cb_args)]
            latched = [c.latch for c in self.by_uri.values() if c.latch is not None]
        for msg in latched:
            self.deliver(msg, [(cb, cb_args)])

    def remove_callback(self, cb: Callable, cb_args: Any) -> None:
        with self.lock:
            for i, (c, a) in enumerate(self.callbacks):
                if c == cb and a == cb_args:
                    self.callbacks = self.callbacks[:i] + self.callbacks[i + 1:]
                    return
        raise KeyError("no matching cb")

    def deliver(self, msg: Any, callbacks: List[Tuple[Callable, Any]] | None = None) -> None:
        """Run every callback (or only ``callbacks``) on ``msg``, in the connection's receive
        thread, as rospy does."""
        for cb, cb_args in self.callbacks if callbacks is None else callbacks:
            try:
                if cb_args is None:
                    cb(msg)
                else:
                    cb(msg, cb_args)
            except Exception:
                if not self.node.is_shutdown():
                    log.logerr(f"bad callback: {cb}\n{traceback.format_exc()}")

    def get_stats(self) -> list:
        return [self.resolved_name,
                [[c.id, c.stat_bytes, c.stat_msgs, -1, c.connected]
                 for c in list(self.by_uri.values())]]

    def get_stats_info(self) -> list:
        return [[c.id, c.pub_uri, "i", c.protocol, self.resolved_name, True, c.info()]
                for c in list(self.by_uri.values()) if c.connected]

    def get_num_connections(self) -> int:
        return sum(1 for c in list(self.by_uri.values()) if c.connected)

    @property
    def connections(self) -> List[PublisherConnection]:
        """The connections, one per publisher (rospy's list: code reads ``callerid_pub``)."""
        return list(self.by_uri.values())

    def has_connection(self, endpoint_id: str) -> bool:
        """Whether we are connected to the publisher whose XML-RPC URI is ``endpoint_id``."""
        conn = self.by_uri.get(endpoint_id)
        return conn is not None and conn.connected

    def close(self) -> None:
        with self.lock:
            self.closed = True
            conns = list(self.by_uri.values())
            self.by_uri = {}
            self.callbacks = []
        for conn in conns:
            conn.close()
        if self.statistics is not None:
            self.statistics.shutdown()
