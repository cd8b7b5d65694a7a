"""Publisher and Subscriber: topic registration, TCPROS connections, queues and latching.

Publishing serializes a message once and hands the same bytes to every subscriber
connection. Each connection has a bounded queue (oldest dropped when full) drained by its own
writer thread; when the queue is empty the publishing thread first tries a non-blocking send
itself, which keeps latency at raw-socket level without ever blocking on a slow subscriber.

Receiving runs one thread per publisher connection: ``recv_into`` a preallocated buffer,
frames cut by ``minros.wire.tcpros.FrameReader`` (large frames land in their own buffer, zero-copy),
deserialize, run the callbacks.
"""

from __future__ import annotations

import collections
import errno
import logging
import select
import socket
import struct
import threading
import time
import traceback
import warnings
from typing import Any, Callable, Dict, List, Tuple

from minros import node as _node_mod
from minros.client import log
from minros.exceptions import (
    ROSException,
    ROSInterruptException,
    ROSSerializationException,
    SerializationError,
)
from minros.msgs import reader_for
from minros.wire import sockets, tcpros, trace
from minros.wire.masterapi import RemoteError
from minros.wire.xmlrpc import ServerProxy

__all__ = [
    "AnyMsg",
    "Publisher",
    "SubscribeListener",
    "Subscriber",
    "Topic",
    "get_published_topics",
    "wait_for_message",
]

_logger = logging.getLogger("minros.client.topics")

DEFAULT_BUFF_SIZE = 65536
#: frames up to this size are joined into one bytes object; larger keep their parts (no copy)
_JOIN_LIMIT = 65536
_U32 = struct.Struct("<I")
_MSG_DONTWAIT = getattr(socket, "MSG_DONTWAIT", 0)
#: a synchronous (queue_size=None) publisher waits at most this long for a slow subscriber
SYNC_SEND_TIMEOUT = 60.0

_conn_ids = iter(range(1, 1 << 62))
_conn_id_lock = threading.Lock()


def _yield_gil() -> None:
    time.sleep(0)


def _next_conn_id() -> int:
    with _conn_id_lock:
        return next(_conn_ids)


# ---------------------------------------------------------------------------------------------
# messages


class AnyMsg:
    """Receives any message type as raw bytes (``_buff``); publishing it re-sends those bytes."""

    __slots__ = ("_buff", "_connection_header")
    _md5sum = tcpros.ANYTYPE
    _type = tcpros.ANYTYPE
    _has_header = False
    _full_text = ""
    _slot_types: List[str] = []

    def __init__(self, *args: Any) -> None:
        if len(args) > 1:
            raise ROSException("AnyMsg does not accept arguments")
        self._buff = args[0] if args else None

    def serialize(self, buff) -> None:
        if self._buff is None:
            raise ROSSerializationException("AnyMsg is not initialized")
        buff.write(self._buff)

    def deserialize(self, data) -> AnyMsg:
        self._buff = data
        return self


class _Chunks:
    """A write-only buffer that keeps the parts a message writes (no concatenation)."""

    __slots__ = ("parts", "size")

    def __init__(self) -> None:
        self.parts: list = []
        self.size = 0

    def write(self, data) -> int:
        if type(data) is not bytes:
            data = bytes(data)  # mutable buffers are snapshotted: the frame may wait in a queue
        self.parts.append(data)
        self.size += len(data)
        return len(data)


class _Discard:
    """Sink for re-running a failed serialization to get the message's own error text."""

    @staticmethod
    def write(_data: Any) -> None:
        pass


_SERIALIZE_ERRORS = (struct.error, TypeError, ValueError, AttributeError, OverflowError,
                     UnicodeError, IndexError, SerializationError)


def serialize_frame(msg: Any) -> Any:
    """Serialize ``msg`` into one frame: ``bytes`` for small messages, else a tuple of buffers
    (length prefix first) that ``sendmsg`` writes without joining them."""
    parts_of = getattr(msg, "_serialize_parts", None)
    if parts_of is None:  # not a minros message class (AnyMsg)
        parts = _parts_written_by(msg)
    else:
        parts = []
        try:
            parts_of(parts.append)
        except NotImplementedError:
            # a hand-written genpy-style class: it subclasses Message but only its
            # serialize() is real (the base _serialize_parts is a stub)
            parts = _parts_written_by(msg)
        except _SERIALIZE_ERRORS:
            _raise_field_error(msg)
            raise
        else:
            if not msg._zero_copy:
                # no array fields that could be views of big buffers (strings, numbers, nested
                # messages): one join, the usual case for every small message
                body = b"".join(parts)
                size = len(body)
                if size <= _JOIN_LIMIT:
                    return _U32.pack(size) + body
                return (_U32.pack(size), body)
    size = 0
    for part in parts:
        size += len(part) if part.__class__ is bytes else memoryview(part).nbytes
    if size <= _JOIN_LIMIT:
        parts.insert(0, _U32.pack(size))
        return b"".join(parts)
    out = [_U32.pack(size)]
    small: list = []
    for part in parts:  # coalesce the many small field writes around the big ones
        n = len(part) if part.__class__ is bytes else memoryview(part).nbytes
        if n < 4096:
            small.append(part)
            continue
        if small:
            out.append(b"".join(small))
            small = []
        # mutable buffers are snapshotted: the frame may wait in a queue after publish returns
        out.append(part if part.__class__ is bytes else bytes(part))
    if small:
        out.append(b"".join(small))
    return tuple(out)


def _parts_written_by(msg: Any) -> list:
    """What ``msg.serialize(buff)`` writes, as a list of ``bytes`` (copies: a frame may wait in
    a queue after publish returns)."""
    chunks = _Chunks()
    try:
        msg.serialize(chunks)
    except ROSSerializationException:
        raise
    except _SERIALIZE_ERRORS as exc:
        raise ROSSerializationException(str(exc)) from None
    return chunks.parts


def _raise_field_error(msg: Any) -> None:
    """Serialize ``msg`` again through serialize(), whose error names the bad field, and raise
    that as ROSSerializationException."""
    try:
        msg.serialize(_Discard)
    except SerializationError as exc:
        raise ROSSerializationException(str(exc)) from None
    except _SERIALIZE_ERRORS as exc:
        raise ROSSerializationException(str(exc)) from None


def _frame_len(frame: Any) -> int:
    if type(frame) is tuple:
        return sum(len(p) for p in frame)
    return len(frame)


def args_kwds_to_message(data_class: Any, args: tuple, kwds: dict) -> Any:
    """rospy's publish(msg | *fields | **fields) convention."""
    if len(args) == 1 and not kwds and args[0].__class__ is data_class:
        return args[0]
    if args and kwds:
        raise TypeError("publish() can be called with arguments or keywords, but not both.")
    if kwds:
        return data_class(**kwds)
    if len(args) == 1:
        arg = args[0]
        if isinstance(arg, data_class):
            return arg
        if hasattr(arg, "_type") and hasattr(arg, "_md5sum") and not isinstance(arg, data_class):
            if getattr(arg, "_type", None) != getattr(data_class, "_type", None):
                raise TypeError(f"expected [{data_class._type}] but got [{arg._type}]")
            return arg
        return data_class(arg)
    return data_class(*args)


# ---------------------------------------------------------------------------------------------
# publisher side


class _PubConnection:
    """One subscriber connected to one of our publications."""

    __slots__ = ("id", "sock", "callerid", "local", "remote", "fileno", "queue", "queue_size",
                 "lock", "cond", "busy", "done", "stat_bytes", "stat_msgs", "impl", "sync", "thread",
                 "header")

    def __init__(self, impl: _PublisherImpl, sock: socket.socket, addr, header: Dict[str, str],
                 queue_size: int | None) -> None:
        self.id = _next_conn_id()
        self.impl = impl
        self.sock = sock
        self.header = header
        self.callerid = header.get("callerid", "")
        self.local = sock.getsockname()
        self.remote = addr
        self.fileno = sock.fileno()
        self.queue: collections.deque = collections.deque()
        self.queue_size = queue_size
        self.lock = threading.Lock()  # C-level `with` on the hot path; cond shares it
        self.cond = threading.Condition(self.lock)
        self.busy = False
        self.done = False
        self.stat_bytes = 0
        self.stat_msgs = 0
        self.sync = queue_size is None
        self.thread: threading.Thread | None = None
        if not self.sync:
            self.thread = threading.Thread(target=self._writer, daemon=True,
                                           name=f"minros-pub:{impl.resolved_name}")
            self.thread.start()
        # a subscriber never sends after its header: a readable socket means it went away
        threading.Thread(target=self._watch_close, daemon=True,
                         name=f"minros-pub-watch:{impl.resolved_name}").start()

    def info(self) -> str:
        return (f"TCPROS connection on port {self.local[1]} to [{self.remote[0]}:{self.remote[1]}"
                f" on socket {self.fileno}]")

    @property
    def endpoint_id(self) -> str:
        """rospy's name for the subscriber's caller id."""
        return self.callerid

    # -- sending ---------------------------------------------------------------------------

    def write(self, frame: Any) -> None:
        """Send one frame: queued publishers never block (the frame waits in the queue for the
        writer thread), queue_size=None ones send it all before returning, as rospy does."""
        if self.done:
            return
        with self.lock:
            if not self.queue and not self.busy:
                # the socket is idle: hand the bytes to the kernel now, without blocking
                try:
                    if frame.__class__ is bytes:
                        try:
                            sent = self.sock.send(frame, _MSG_DONTWAIT)
                        except BlockingIOError:
                            sent = 0
                        self.stat_bytes += sent
                        if sent == len(frame):  # all of it in one call: the usual case
                            self.stat_msgs += 1
                            return
                        rest = _Partial(memoryview(frame)[sent:])
                    else:
                        rest = self._send_nowait(frame)
                        if rest is None:
                            return
                    if self.sync:
                        self._send_sync(rest)
                        return
                except OSError as exc:
                    self._fail(exc)
                    return
                self.queue.append(rest)
                self.cond.notify()
                return
            queue = self.queue
            if self.queue_size and len(queue) >= self.queue_size:
                # drop the oldest, but never the half-sent frame at the front
                if type(queue[0]) is _Partial:
                    if len(queue) > 1:
                        del queue[1]
                else:
                    queue.popleft()
            queue.append(frame)
            self.cond.notify()
        # The writer thread is behind: let it have the GIL now rather than after the
        # interpreter's switch interval (5 ms), or a publishing loop starves it.
        _yield_gil()

    def _send_sync(self, rest: _Partial) -> None:
        """queue_size=None: send the unsent ``rest`` of a frame before returning, but give up
        on a subscriber that takes nothing for SYNC_SEND_TIMEOUT seconds. The socket stays in
        blocking mode (no timeout), so the common case never gets here."""
        parts = list(rest.parts)
        deadline = time.monotonic() + SYNC_SEND_TIMEOUT
        poller = select.poll()  # not select(): descriptors may be above FD_SETSIZE
        poller.register(self.sock, select.POLLOUT)
        while parts:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError(f"subscriber took nothing for {SYNC_SEND_TIMEOUT:.0f} s")
            poller.poll(min(remaining, 1.0) * 1000)
            try:
                sent = self.sock.sendmsg(parts, (), _MSG_DONTWAIT)
            except BlockingIOError:
                continue
            if sent:
                deadline = time.monotonic() + SYNC_SEND_TIMEOUT  # it is reading: keep waiting
            self.stat_bytes += sent
            rest = _advance(parts, sent)
            parts = list(rest.parts) if rest is not None else []
        self.stat_msgs += 1

    def _send_nowait(self, frame: Any) -> Any:
        """Send what the kernel takes without blocking; return the unsent rest or None."""
        sock = self.sock
        if type(frame) is tuple:
            parts = list(frame)
            total = sum(len(p) for p in parts)
            try:
                sent = sock.sendmsg(parts, (), _MSG_DONTWAIT)
            except BlockingIOError:
                sent = 0
            self.stat_bytes += sent
            if sent == total:
                self.stat_msgs += 1
                return None
            return _advance(parts, sent)
        try:
            sent = sock.send(frame, _MSG_DONTWAIT)
        except BlockingIOError:
            sent = 0
        self.stat_bytes += sent
        if sent == len(frame):
            self.stat_msgs += 1
            return None
        return _Partial(memoryview(frame)[sent:])

    def _send_blocking(self, frame: Any) -> None:
        sock = self.sock
        if type(frame) is tuple:
            parts = list(frame)
            while parts:
                sent = sock.sendmsg(parts)
                self.stat_bytes += sent
                rest = _advance(parts, sent)
                parts = list(rest.parts) if rest is not None else []
        elif type(frame) is _Partial:
            parts = frame.parts
            for part in parts:
                sock.sendall(part)
                self.stat_bytes += len(part)
            self.stat_msgs += 1
            return
        else:
            sock.sendall(frame)
            self.stat_bytes += len(frame)
        self.stat_msgs += 1

    def _writer(self) -> None:
        cond = self.cond
        while True:
            with cond:
                self.busy = False
                while not self.queue and not self.done:
                    cond.wait()
                if self.done:
                    return
                batch = list(self.queue)
                self.queue.clear()
                self.busy = True
            try:
                if len(batch) > 1 and all(type(f) is bytes for f in batch):
                    # many small frames: one system call for the lot
                    joined = b"".join(batch)
                    self.sock.sendall(joined)
                    self.stat_bytes += len(joined)
                    self.stat_msgs += len(batch)
                else:
                    for frame in batch:
                        self._send_blocking(frame)
            except OSError as exc:
                with cond:
                    self._fail(exc)
                return

    def _watch_close(self) -> None:
        try:
            while not self.done:
                data = self.sock.recv(4096)
                if not data:
                    break
        except OSError:
            pass
        if not self.done:
            with self.cond:
                self._fail(None)

    def _fail(self, exc: BaseException | None) -> None:
        """Called with ``cond`` held: the connection is dead, forget it."""
        if self.done:
            return
        self.done = True
        self.queue.clear()
        self.cond.notify_all()
        if exc is not None and not isinstance(exc, (BrokenPipeError, ConnectionResetError)):
            _logger.info("publisher connection to [%s] on [%s] closed: %s",
                         self.callerid, self.impl.resolved_name, exc)
        sockets.close(self.sock)
        threading.Thread(target=self.impl._remove_connection, args=(self,), daemon=True,
                         name=f"minros-pub-close:{self.impl.resolved_name}").start()

    def close(self) -> None:
        if self.done:
            return
        # First wake a send in progress (a queue_size=None publish to a slow reader holds the
        # lock for as long as the reader keeps taking bytes): it fails with EPIPE at once.
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        with self.cond:
            if self.done:
                return
            self.done = True
            self.queue.clear()
            self.cond.notify_all()
        sockets.close(self.sock)


class _Partial:
    """The unsent rest of a frame (after a partial non-blocking send)."""

    __slots__ = ("parts",)

    def __init__(self, *parts: Any) -> None:
        self.parts = parts


def _advance(parts: list, sent: int) -> _Partial | None:
    rest = []
    for part in parts:
        n = len(part)
        if sent >= n:
            sent -= n
            continue
        rest.append(memoryview(part)[sent:] if sent else part)
        sent = 0
    return _Partial(*rest) if rest else None


class _PublisherImpl:
    """Shared state of all Publisher handles for one topic in this process."""

    def __init__(self, node: _node_mod.Node, name: str, resolved_name: str, data_class: Any) -> None:
        self.node = node
        self.name = name
        self.resolved_name = resolved_name
        self.data_class = data_class
        self.type = data_class._type
        self.md5sum = data_class._md5sum
        self.connections: List[_PubConnection] = []
        self.lock = threading.RLock()
        self.listeners: List[Any] = []
        self.headers: Dict[str, str] = {}
        self.is_latch = False
        self.latch: Any = None
        self.queue_size: int | None = None
        self.tcp_nodelay = False
        self.seq = 0
        self.message_data_sent = 0
        self.ref_count = 0
        self.closed = False

    # -- connections ---------------------------------------------------------------------

    def accept_subscriber(self, sock: socket.socket, addr, header: Dict[str, str]) -> str | None:
        """Inbound connection from a subscriber (called by the node's TCPROS server)."""
        error = tcpros.publisher_header_error(
            header, self.node.caller_id, {self.resolved_name: (self.type, self.md5sum)})
        if error is not None:
            return error
        if self.closed:
            return f"Internal error processing topic [{self.resolved_name}]"
        nodelay = header.get("tcp_nodelay", "").strip() == "1" if "tcp_nodelay" in header else self.tcp_nodelay
        if nodelay:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        fields = {
            "topic": self.resolved_name,
            "type": self.type,
            "latching": "1" if self.is_latch else "0",
            "message_definition": self.data_class._full_text,
            "md5sum": self.md5sum,
            "callerid": self.node.caller_id,
        }
        fields.update(self.headers)
        sock.sendall(tcpros.encode_header(fields))
        with self.lock:
            conn = _PubConnection(self, sock, addr, header, self.queue_size)
            self.connections = self.connections + [conn]
            if self.is_latch and self.latch is not None:
                frame = self._serialize(self.latch)
                conn.write(frame)
        for listener in list(self.listeners):
            def publish_single(*args: Any, _conn: _PubConnection = conn, **kwds: Any) -> None:
                msg = args_kwds_to_message(self.data_class, args, kwds)
                with self.lock:
                    _conn.write(self._serialize(msg))
            try:
                listener.peer_subscribe(self.resolved_name, self._publish_any, publish_single)
            except Exception:
                _logger.error("peer_subscribe failed: %s", traceback.format_exc())
        return None

    def _publish_any(self, *args: Any, **kwds: Any) -> None:
        self.publish(args_kwds_to_message(self.data_class, args, kwds))

    def _remove_connection(self, conn: _PubConnection) -> None:
        with self.lock:
            if conn not in self.connections:
                return
            self.connections = [c for c in self.connections if c is not conn]
            remaining = len(self.connections)
        for listener in list(self.listeners):
            try:
                listener.peer_unsubscribe(self.resolved_name, remaining)
            except Exception:
                _logger.error("peer_unsubscribe failed: %s", traceback.format_exc())

    # -- publishing ----------------------------------------------------------------------

    def _serialize(self, msg: Any) -> Any:
        """Called with the lock held: Header.seq auto-fill, then one serialization."""
        self.seq += 1
        tcpros.stamp_header(msg, self.seq)
        frame = serialize_frame(msg)
        self.message_data_sent += _frame_len(frame) - 4
        return frame

    def publish(self, msg: Any) -> None:
        with self.lock:
            if self.closed:
                if self.node.is_shutdown():
                    return
                raise ROSException("publish() to a closed topic")
            if self.is_latch:
                self.latch = msg
            conns = self.connections
            if not conns:
                return
            # Header auto-fill, then one serialization for every connection
            self.seq += 1
            if getattr(msg, "_has_header", False):
                tcpros.stamp_header(msg, self.seq)
            frame = serialize_frame(msg)
            self.message_data_sent += (len(frame) if frame.__class__ is bytes else _frame_len(frame)) - 4
            for conn in conns:
                conn.write(frame)

    # -- bookkeeping ---------------------------------------------------------------------

    def get_stats(self) -> list:
        return [self.resolved_name, self.message_data_sent,
                [[c.id, c.stat_bytes, c.stat_msgs, not c.done] for c in self.connections]]

    def has_connection(self, endpoint_id: str) -> bool:
        """rospy's query: is the subscriber node ``endpoint_id`` (its caller id) connected?"""
        return any(c.callerid == endpoint_id and not c.done for c in self.connections)

    def has_connections(self) -> bool:
        return any(not c.done for c in self.connections)

    def get_stats_info(self) -> list:
        return [[c.id, c.callerid, "o", "TCPROS", self.resolved_name, True, c.info()]
                for c in self.connections]

    def close(self) -> None:
        with self.lock:
            self.closed = True
            conns, self.connections = self.connections, []
        for conn in conns:
            conn.close()


# ---------------------------------------------------------------------------------------------
# subscriber side


class _SubConnection:
    """Our connection to one publisher of a subscribed topic (runs in its own thread)."""

    def __init__(self, impl: _SubscriberImpl, pub_uri: str) -> None:
        self.id = _next_conn_id()
        self.impl = impl
        self.pub_uri = pub_uri
        self.sock: socket.socket | None = None
        self.header: Dict[str, str] = {}
        self.latch: Any = None
        self.done = False
        self.connected = False
        self.stat_bytes = 0
        self.stat_msgs = 0
        self.local: Tuple[Any, ...] = ("", 0)
        self.remote: Tuple[Any, ...] = ("", 0)
        self.fileno = -1
        self.gen = 0
        self.reported: set = set()
        self.reader: tcpros.FrameReader | None = None
        self.pending: list = []
        self.thread = threading.Thread(target=self._run, daemon=True,
                                       name=f"minros-sub:{impl.resolved_name}")

    def info(self) -> str:
        return (f"TCPROS connection on port {self.local[1]} to [{self.remote[0]}:{self.remote[1]}"
                f" on socket {self.fileno}]")

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
        sock = self.sock
        if sock is not None:
            sockets.close(sock)

    # -- connection life ---------------------------------------------------------------------

    def _run(self) -> None:
        interval = 0.5
        node = self.impl.node
        try:
            while not self.done and not node.is_shutdown():
                try:
                    address = self._request_topic()
                except OSError as exc:
                    if _is_refused(exc):
                        _logger.debug("publisher %s is gone: %s", self.pub_uri, exc)
                        return
                    address = None
                    _logger.debug("requestTopic to %s failed: %s", self.pub_uri, exc)
                except _GiveUp as exc:
                    _logger.debug("not connecting to %s: %s", self.pub_uri, exc)
                    return
                if address is not None:
                    try:
                        if self._connect(*address):
                            interval = 0.5
                            self._receive_loop()
                    except (OSError, tcpros.HeaderError, tcpros.FrameError, _Rejected) as exc:
                        text = str(exc)
                        if isinstance(exc, (ConnectionResetError, ConnectionAbortedError,
                                            BrokenPipeError)):
                            # the publisher went away (killed): not worth a console line
                            _logger.debug("publisher %s went away: %s", self.pub_uri, text)
                        elif (not self.done and not node.is_shutdown_requested()
                                and text not in self.reported):
                            # one line per distinct failure, not one per retry
                            self.reported.add(text)
                            log.logwarn(f"[{self.impl.resolved_name}] connection to publisher "
                                      f"[{self.pub_uri}] failed: {text}")
                    finally:
                        self.connected = False
                        if self.sock is not None:
                            sockets.close(self.sock)
                            self.sock = None
                if self.done or node.is_shutdown_requested():
                    return
                if self.pub_uri not in self.impl.publisher_uris:
                    return
                if node.wait_for_shutdown(interval):
                    return
                interval = min(interval * 2, 8.0)
        finally:
            self.impl._connection_ended(self)

    def _request_topic(self) -> Tuple[str, int] | None:
        proxy = ServerProxy(self.pub_uri, timeout=5.0)
        try:
            code, msg, params = proxy.requestTopic(self.impl.node.caller_id, self.impl.resolved_name,
                                                   [[tcpros.TCPROS]])
        finally:
            proxy.close()
        if code != 1:
            raise _GiveUp(f"requestTopic: {msg}")
        if (not isinstance(params, list) or len(params) != 3 or params[0] != tcpros.TCPROS
                or not isinstance(params[2], int)):
            raise _GiveUp(f"publisher returned invalid protocol choice: {params}")
        return params[1], params[2]

    def _connect(self, host: str, port: int) -> bool:
        impl = self.impl
        sock = trace.watch(socket.create_connection((host, port), timeout=10.0), "connect")
        self.sock = sock
        if self.done:
            return False
        if impl.tcp_nodelay:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        data_class = impl.data_class
        sock.sendall(tcpros.encode_header({
            "topic": impl.resolved_name,
            "message_definition": data_class._full_text,
            "tcp_nodelay": "1" if impl.tcp_nodelay else "0",
            "md5sum": data_class._md5sum,
            "type": data_class._type,
            "callerid": impl.node.caller_id,
        }))
        header = sockets.read_header(sock)  # exactly the header: the messages follow
        error = tcpros.subscriber_header_error(header, impl.resolved_name, data_class._md5sum,
                                               data_class._type)
        if error is not None:
            raise _Rejected(error)
        sock.settimeout(None)
        self.header = header
        self.local = sock.getsockname()
        self.remote = sock.getpeername()
        self.fileno = sock.fileno()
        self.reader = tcpros.FrameReader(buff_size=max(impl.buff_size, 4096),
                                         reuse_big=not getattr(data_class, "_keeps_buffer", True))
        self.pending = []
        self.connected = True
        return True

    def _receive_loop(self) -> None:
        impl = self.impl
        reader = self.reader
        header = self.header
        latching = header.get("latching", "0") == "1"
        read = reader_for(impl.data_class)
        deliver = impl.deliver if impl.statistics is None else impl.statistics.wrap(self, impl.deliver)
        frames = self.pending
        recv_into = self.sock.recv_into
        received_frames = reader.received_frames
        recv_buffer = reader.recv_buffer
        while True:
            if frames:
                queue_size = impl.queue_size
                if queue_size is not None and len(frames) > queue_size:
                    frames = frames[-queue_size:]  # older ones dropped, as in rospy
                for frame in frames:
                    self.stat_msgs += 1
                    try:
                        msg = read(frame)
                    except Exception as exc:
                        log.logerr(f"[{impl.resolved_name}] error deserializing incoming message "
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
            if self.done:
                return
            n = recv_into(recv_buffer())
            if not n:
                reader.eof()
                return
            self.stat_bytes += n
            frames = received_frames(n)


class _GiveUp(Exception):
    pass


class _Rejected(Exception):
    pass


def _is_refused(exc: BaseException) -> bool:
    return isinstance(exc, ConnectionRefusedError) or getattr(exc, "errno", None) == errno.ECONNREFUSED


class _SubscriberImpl:
    """Shared state of all Subscriber handles for one topic: one connection per publisher."""

    def __init__(self, node: _node_mod.Node, name: str, resolved_name: str, data_class: Any) -> None:
        self.node = node
        self.name = name
        self.resolved_name = resolved_name
        self.data_class = data_class
        self.type = data_class._type
        self.md5sum = data_class._md5sum
        self.callbacks: List[Tuple[Callable, Any]] = []
        self.queue_size: int | None = None
        self.buff_size = DEFAULT_BUFF_SIZE
        self.tcp_nodelay = False
        #: publisher XML-RPC URI -> our connection to it
        self.by_uri: Dict[str, _SubConnection] = {}
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
                    conn = _SubConnection(self, uri)
                    conn.gen = self.update_gen
                    self.by_uri[uri] = conn
                    fresh.append(conn)
        for conn in fresh:
            conn.thread.start()

    def _connection_ended(self, conn: _SubConnection) -> None:
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
            self._invoke(msg, cb, cb_args)

    def remove_callback(self, cb: Callable, cb_args: Any) -> None:
        with self.lock:
            for i, (c, a) in enumerate(self.callbacks):
                if c == cb and a == cb_args:
                    self.callbacks = self.callbacks[:i] + self.callbacks[i + 1:]
                    return
        raise KeyError("no matching cb")

    def deliver(self, msg: Any) -> None:
        """Run every callback on ``msg`` (in the connection's receive thread, as rospy does)."""
        for cb, cb_args in self.callbacks:
            try:
                if cb_args is None:
                    cb(msg)
                else:
                    cb(msg, cb_args)
            except Exception:
                if not self.node.is_shutdown():
                    log.logerr(f"bad callback: {cb}\n{traceback.format_exc()}")

    @staticmethod
    def _invoke(msg: Any, cb: Callable, cb_args: Any) -> None:
        try:
            if cb_args is not None:
                cb(msg, cb_args)
            else:
                cb(msg)
        except Exception:
            log.logerr(f"bad callback: {cb}\n{traceback.format_exc()}")

    def get_stats(self) -> list:
        return [self.resolved_name,
                [[c.id, c.stat_bytes, c.stat_msgs, -1, c.connected]
                 for c in list(self.by_uri.values())]]

    def get_stats_info(self) -> list:
        return [[c.id, c.pub_uri, "i", "TCPROS", self.resolved_name, True, c.info()]
                for c in list(self.by_uri.values()) if c.connected]

    def get_num_connections(self) -> int:
        return sum(1 for c in list(self.by_uri.values()) if c.connected)

    @property
    def connections(self) -> List[_SubConnection]:
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


# ---------------------------------------------------------------------------------------------
# process-wide topic bookkeeping

#: guards the reference counts of the publication/subscription objects (a leaf: the master
#: is called outside it, so a slow master does not block other threads' Publisher() calls)
_impl_lock = threading.Lock()
#: makes a new subscription's topic statistics (or None); set by init_node (client/statistics)
#: so that the receive loop wraps its deliver only when statistics are on
statistics_factory: Callable[[Any], Any] | None = None


def _acquire(kind: str, name: str, data_class: Any) -> Any:
    if not isinstance(name, str) or not name:
        raise ValueError("topic name must be a non-empty string")
    if data_class is None or not hasattr(data_class, "_md5sum"):
        raise ValueError(f"data_class [{data_class}] is not a message data class")
    me = _node_mod.default_node()
    resolved = me.resolve_topic_name(name)
    registry = me.publications if kind == "pub" else me.subscriptions
    with _impl_lock:
        impl = registry.get(resolved)
        fresh = impl is None or impl.closed
        if fresh:
            cls = _PublisherImpl if kind == "pub" else _SubscriberImpl
            impl = cls(me, name, resolved, data_class)
        elif impl.md5sum != data_class._md5sum and tcpros.ANYTYPE not in (impl.md5sum, data_class._md5sum):
            raise ROSException(
                f"{'publisher' if kind == 'pub' else 'subscriber'} for [{resolved}] already exists "
                f"with a different type [{impl.type}]")
        impl.ref_count += 1
        if fresh:  # in the registry at once, so that a second Publisher() finds this one
            if kind == "pub":
                me.add_publication(impl, announce=False)
            else:
                me.add_subscription(impl, announce=False)
    if fresh:  # the master round trips happen outside the lock
        if kind == "sub" and statistics_factory is not None:
            impl.statistics = statistics_factory(impl)  # before any connection starts
        me.announce(kind, impl)
    return impl


def _release(kind: str, impl: Any) -> None:
    with _impl_lock:
        impl.ref_count -= 1
        if impl.ref_count > 0:
            return
        impl.close()
    if kind == "pub":
        impl.node.remove_publication(impl)
    else:
        impl.node.remove_subscription(impl)


class Topic:
    """Base of Publisher and Subscriber (rospy.topics.Topic)."""

    _kind = ""

    def __init__(self, name: str, data_class: Any) -> None:
        self.impl = _acquire(self._kind, name, data_class)
        self.name = self.impl.resolved_name
        self.resolved_name = self.impl.resolved_name
        self.data_class = data_class
        self.type = data_class._type
        self.md5sum = data_class._md5sum
        self.reg_type = self._kind

    def get_num_connections(self) -> int:
        impl = self.impl
        if impl is None:
            return 0
        if self._kind == "pub":
            return sum(1 for c in impl.connections if not c.done)
        return impl.get_num_connections()

    def unregister(self) -> None:
        impl, self.impl = self.impl, None
        if impl is not None:
            _release(self._kind, impl)


class SubscribeListener:
    """Notified when subscribers connect to or disconnect from a Publisher."""

    def peer_subscribe(self, topic_name: str, topic_publish: Callable, peer_publish: Callable) -> None:
        pass

    def peer_unsubscribe(self, topic_name: str, num_peers: int) -> None:
        pass


class Publisher(Topic):
    """Publish messages of ``data_class`` on topic ``name`` (rospy.Publisher)."""

    _kind = "pub"

    def __init__(self, name: str, data_class: Any, subscriber_listener: SubscribeListener | None = None,
                 tcp_nodelay: bool = False, latch: bool = False, headers: Dict[str, str] | None = None,
                 queue_size: int | None = None) -> None:
        super().__init__(name, data_class)
        impl = self.impl
        if subscriber_listener:
            impl.listeners.append(subscriber_listener)
        if tcp_nodelay:
            impl.tcp_nodelay = True
        if latch:
            impl.is_latch = True
        if headers:
            impl.headers.update({str(k): str(v) for k, v in headers.items()})
        if queue_size is not None:
            if not isinstance(queue_size, int) or queue_size < 0:
                raise ROSException("queue_size must be a non-negative integer or None")
            impl.queue_size = queue_size
        else:
            warnings.warn(
                "The publisher should be created with an explicit keyword argument 'queue_size'. "
                "Please see http://wiki.ros.org/rospy/Overview/Publishers%20and%20Subscribers "
                "for more information.", SyntaxWarning, stacklevel=2)

    def publish(self, *args: Any, **kwds: Any) -> None:
        """Publish a message instance, or build one from positional or keyword fields."""
        impl = self.impl
        if impl is None:
            raise ROSException("publish() to an unregistered() handle")
        if not impl.node.initialized:
            raise ROSException("ROS node has not been initialized yet. Please call init_node() first")
        if len(args) == 1 and not kwds and args[0].__class__ is self.data_class:
            impl.publish(args[0])  # the common case, without the argument juggling
        else:
            impl.publish(args_kwds_to_message(self.data_class, args, kwds))


class Subscriber(Topic):
    """Receive messages of ``data_class`` on topic ``name`` (rospy.Subscriber)."""

    _kind = "sub"

    def __init__(self, name: str, data_class: Any, callback: Callable | None = None,
                 callback_args: Any = None, queue_size: int | None = None,
                 buff_size: int = DEFAULT_BUFF_SIZE, tcp_nodelay: bool = False) -> None:
        super().__init__(name, data_class)
        impl = self.impl
        if queue_size is not None:
            if queue_size == -1:
                queue_size = None
            elif queue_size == 0:
                raise ROSException("queue size may not be set to zero")
            elif type(queue_size) is not int:
                raise ROSException("queue size must be an integer")
            impl.queue_size = queue_size
        if buff_size != DEFAULT_BUFF_SIZE:
            if type(buff_size) is not int:
                raise ROSException("buffer size must be an integer")
            if buff_size <= 0:
                raise ROSException("buffer size must be a positive integer")
            impl.buff_size = buff_size
        if tcp_nodelay:
            impl.tcp_nodelay = True
        self.callback = callback
        self.callback_args = callback_args
        if callback is not None:
            impl.add_callback(callback, callback_args)

    def unregister(self) -> None:
        impl = self.impl
        if impl is not None and self.callback is not None:
            try:
                impl.remove_callback(self.callback, self.callback_args)
            except KeyError:
                pass
        self.callback = self.callback_args = None
        super().unregister()


# ---------------------------------------------------------------------------------------------
# helpers


def wait_for_message(topic: str, topic_type: Any, timeout: float | None = None) -> Any:
    """Subscribe to ``topic`` and return its next message (rospy.wait_for_message)."""
    if timeout is not None and hasattr(timeout, "to_sec"):
        timeout = timeout.to_sec()  # rospy accepts a Duration
    received: list = []
    event = threading.Event()

    def callback(msg: Any) -> None:
        if not received:
            received.append(msg)
            event.set()

    sub = Subscriber(topic, topic_type, callback)
    try:
        deadline = None if timeout is None else time.monotonic() + timeout
        while not event.is_set():
            if _node_mod.is_shutdown():
                raise ROSInterruptException("rospy shutdown")
            remaining = 0.01 if deadline is None else min(0.01, deadline - time.monotonic())
            if remaining <= 0:
                raise ROSException(f"timeout exceeded while waiting for message on topic {topic}")
            event.wait(remaining)
        return received[0]
    finally:
        sub.unregister()


def get_published_topics(namespace: str = "/") -> List[List[str]]:
    """[[topic, type], ...] published in ``namespace`` (master getPublishedTopics)."""
    try:
        return [list(pair) for pair in _node_mod.master().get_published_topics(namespace)]
    except RemoteError as exc:
        raise ROSException(f"unable to get published topics: {exc}") from None

