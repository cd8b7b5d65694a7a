"""TCPROS for topics: the publisher's end, the subscriber's end, and the protocol handler.

The publisher's end (:class:`TCPROSSender`) keeps latency at raw-socket level without
making a queued publisher wait for a slow subscriber: ``send`` first tries one non-blocking
send in the publishing thread; only what the kernel did not take waits in a bounded queue
(oldest dropped when full, never a half-sent frame) for the connection's writer thread. A
publisher that is a whole queue ahead gives the writer a big frame's send time (BACKOFF_*)
to take a frame before it drops one: a loop publishing images faster than the wire would
otherwise spin and take the CPU the writer needs (6 ms for a 1920x1080 image, nothing for a
small message). A
``queue_size=None`` publisher sends everything before ``send`` returns, as rospy does, but
gives up on a subscriber that takes nothing for SYNC_SEND_TIMEOUT seconds.

The subscriber's end (:class:`TCPROSReceiver`) receives into a preallocated buffer and cuts
frames with ``minros.wire.tcpros.FrameReader`` (a large frame lands in a buffer of its own,
zero-copy). :class:`TCPROSHandler` is TCPROS as a :class:`~minros.transport.base.ProtocolHandler`:
requestTopic's answer is the node's TCPROS server address, and the server hands it every
inbound topic connection no other handler claims.
"""

from __future__ import annotations

import collections
import logging
import socket
import threading
import time
from typing import Any, Callable, Deque, Dict, List, Tuple

from minros.transport import streams
from minros.transport.base import Frame, ProtocolHandler, PublicationSide, Transport
from minros.transport.streams import MSG_DONTWAIT, wait_writable
from minros.transport.tcpros_base import TCPROS, TCPROSTransport, connect, negotiate
from minros.wire import sockets, tcpros
from minros.wire.handshake import Handshake, Role, route

__all__ = ["SYNC_SEND_TIMEOUT", "TCPROSHandler", "TCPROSReceiver", "TCPROSSender"]

_logger = logging.getLogger("minros.transport.tcpros")

#: a synchronous (queue_size=None) publisher waits at most this long for a slow subscriber
SYNC_SEND_TIMEOUT = 60.0
#: a publisher whose subscriber is a whole queue behind waits for the writer to take a frame
#: for as long as its frame takes to send at this many bytes per second (loopback's order),
#: at most BACKOFF_MAX seconds and not at all below BACKOFF_MIN: a 1920x1080 image 6 ms, a
#: small message never
BACKOFF_RATE = 1e9
BACKOFF_MAX = 0.01
BACKOFF_MIN = 50e-6


def _yield_gil() -> None:
    time.sleep(0)


# ---------------------------------------------------------------------------------------------
# the publisher's end


class _Partial:
    """The unsent rest of a frame (after a partial non-blocking send)."""

    __slots__ = ("parts",)

    def __init__(self, *parts: Any) -> None:
        self.parts = parts


def _advance(parts: List[Any], sent: int) -> _Partial | None:
    rest = []
    for part in parts:
        n = len(part)
        if sent >= n:
            sent -= n
            continue
        rest.append(memoryview(part)[sent:] if sent else part)
        sent = 0
    return _Partial(*rest) if rest else None


class TCPROSSender(TCPROSTransport):
    """The publisher's end of one subscriber's TCPROS connection.

    ``on_close(self)`` runs once, in a thread of its own, when the connection fails or the
    subscriber leaves (not when :meth:`close` is called)."""

    def __init__(self, stream: Any, topic: str, queue_size: int | None,
                 on_close: Callable[[Transport], Any]) -> None:
        super().__init__(stream, topic)
        self.bytes_sent = 0
        self.queue: Deque[Any] = collections.deque()
        self.queue_size = queue_size
        self.sync = queue_size is None
        self.lock = threading.Lock()  # C-level `with` on the hot path; cond shares it
        self.cond = threading.Condition(self.lock)  # the writer waits here for frames
        self.space = threading.Condition(self.lock)  # a publisher, for room in a full queue
        self.room_wanted = 0  # publishers waiting on space
        self.busy = False
        self.on_close = on_close
        self.thread: threading.Thread | None = None

    @property
    def stat_bytes(self) -> int:
        return self.bytes_sent

    @property
    def callerid(self) -> str:
        return self.header.get("callerid", "")

    @property
    def endpoint_id(self) -> str:
        """rospy's name for the subscriber's caller id."""
        return self.callerid

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        """Answer the subscriber's ``opening`` header; once open, the connection's threads
        start (a writer unless synchronous, and one that notices the subscriber leave)."""
        self.header = negotiate(self.stream, handshake, opening)
        if not self.sync:
            self.thread = threading.Thread(target=self._writer, daemon=True,
                                           name=f"minros-pub:{self.topic}")
            self.thread.start()
        # a subscriber never sends after its header: a readable socket means it went away
        threading.Thread(target=self._watch_close, daemon=True,
                         name=f"minros-pub-watch:{self.topic}").start()

    # -- sending ---------------------------------------------------------------------------

    def send(self, frame: Frame) -> None:
        """Send one frame: queued publishers do not wait for the subscriber (the frame waits
        in the queue for the writer thread; a full queue makes a big frame wait a moment for
        room), queue_size=None ones send it all before returning, as rospy does."""
        if self.done:
            return
        with self.lock:
            if not self.queue and not self.busy:
                # the socket is idle: hand the bytes to the kernel now, without blocking
                try:
                    if frame.__class__ is bytes:
                        try:
                            sent = self.stream.send(frame, MSG_DONTWAIT)
                        except BlockingIOError:
                            sent = 0
                        self.bytes_sent += sent
                        if sent == len(frame):  # all of it in one call: the usual case
                            self.stat_msgs += 1
                            return
                        rest: Any = _Partial(memoryview(frame)[sent:])
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
                # A whole queue behind: a publishing loop would only spin here, dropping
                # frames, and take the CPU the writer (and the subscriber) need. Give the
                # writer a big frame's send time to take one first (nothing for a small one).
                wait = (len(frame) if frame.__class__ is bytes else sum(map(len, frame))) / BACKOFF_RATE
                if wait >= BACKOFF_MIN:
                    self.room_wanted += 1
                    self.space.wait(min(wait, BACKOFF_MAX))
                    self.room_wanted -= 1
                    if self.done:
                        return
            if self.queue_size and len(queue) >= self.queue_size:
                # drop the oldest, but never the half-sent frame at the front
                if type(queue[0]) is _Partial:
                    if len(queue) > 1:
                        del queue[1]
                else:
                    queue.popleft()
            queue.append(frame)
            if not self.busy:  # a busy writer takes it without being told (and a notify
                self.cond.notify()  # costs a microsecond even with no one waiting)
        # The writer thread is behind: let it have the GIL now rather than after the
        # interpreter's switch interval (5 ms), or a publishing loop starves it.
        _yield_gil()

    def _send_sync(self, rest: _Partial) -> None:
        """queue_size=None: send the unsent ``rest`` of a frame before returning, but give up
        on a subscriber that takes nothing for SYNC_SEND_TIMEOUT seconds. The socket stays in
        blocking mode (no timeout), so the common case never gets here."""
        parts = list(rest.parts)
        deadline = time.monotonic() + SYNC_SEND_TIMEOUT
        while parts:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError(f"subscriber took nothing for {SYNC_SEND_TIMEOUT:.0f} s")
            wait_writable(self.stream, min(remaining, 1.0))
            try:
                sent = self.stream.sendmsg(parts, (), MSG_DONTWAIT)
            except BlockingIOError:
                continue
            if sent:
                deadline = time.monotonic() + SYNC_SEND_TIMEOUT  # it is reading: keep waiting
            self.bytes_sent += sent
            more = _advance(parts, sent)
            parts = list(more.parts) if more is not None else []
        self.stat_msgs += 1

    def _send_nowait(self, frame: Any) -> Any:
        """Send what the kernel takes without blocking; return the unsent rest or None."""
        stream = self.stream
        if type(frame) is tuple:
            parts = list(frame)
            total = sum(len(p) for p in parts)
            try:
                sent = stream.sendmsg(parts, (), MSG_DONTWAIT)
            except BlockingIOError:
                sent = 0
            self.bytes_sent += sent
            if sent == total:
                self.stat_msgs += 1
                return None
            return _advance(parts, sent)
        try:
            sent = stream.send(frame, MSG_DONTWAIT)
        except BlockingIOError:
            sent = 0
        self.bytes_sent += sent
        if sent == len(frame):
            self.stat_msgs += 1
            return None
        return _Partial(memoryview(frame)[sent:])

    def _send_blocking(self, frame: Any) -> None:
        stream = self.stream
        if type(frame) is tuple:
            parts = list(frame)
            while parts:
                sent = stream.sendmsg(parts)
                self.bytes_sent += sent
                rest = _advance(parts, sent)
                parts = list(rest.parts) if rest is not None else []
        elif type(frame) is _Partial:
            for part in frame.parts:
                stream.sendall(part)
                self.bytes_sent += len(part)
        else:
            stream.sendall(frame)
            self.bytes_sent += len(frame)
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
                queue = self.queue
                if queue[0].__class__ is bytes:  # small frames: all of them, in one send
                    batch = list(queue)
                    queue.clear()
                else:  # a big frame: one at a time, so that the queue keeps the newest
                    batch = [queue.popleft()]
                self.busy = True
                if self.room_wanted:  # (a notify costs a microsecond even with no one waiting)
                    self.space.notify()
            try:
                if len(batch) > 1 and all(type(f) is bytes for f in batch):
                    # many small frames: one system call for the lot
                    joined = b"".join(batch)
                    self.stream.sendall(joined)
                    self.bytes_sent += len(joined)
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
                if not self.stream.recv(4096):
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
        self.space.notify_all()
        if exc is not None and not isinstance(exc, (BrokenPipeError, ConnectionResetError)):
            _logger.info("publisher connection to [%s] on [%s] closed: %s",
                         self.callerid, self.topic, exc)
        sockets.close(self.stream)
        # outside our lock: the publication takes its own (which is taken before ours)
        threading.Thread(target=self.on_close, args=(self,), daemon=True,
                         name=f"minros-pub-close:{self.topic}").start()

    def close(self) -> None:
        if self.done:
            return
        # First wake a send in progress (a queue_size=None publish to a slow reader holds the
        # lock for as long as the reader keeps taking bytes): it fails with EPIPE at once.
        try:
            self.stream.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        with self.cond:
            if self.done:
                return
            self.done = True
            self.queue.clear()
            self.cond.notify_all()
            self.space.notify_all()
        sockets.close(self.stream)


# ---------------------------------------------------------------------------------------------
# the subscriber's end


class TCPROSReceiver(TCPROSTransport):
    """The subscriber's end of its TCPROS connection to one publisher."""

    def __init__(self, stream: Any, topic: str, buff_size: int, reuse_big: bool) -> None:
        super().__init__(stream, topic)
        self.reader = tcpros.FrameReader(buff_size=max(buff_size, 4096), reuse_big=reuse_big)
        # the hot path: a closure over what it calls, one Python call per recv in all
        self.receive = self._receiver()  # type: ignore[method-assign]

    @property
    def stat_bytes(self) -> int:
        return self.reader.bytes_received

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        """Send our header and check the publisher's; the stream blocks without a timeout
        afterwards (frames may be far apart)."""
        self.header = negotiate(self.stream, handshake)
        self.stream.settimeout(None)
        self.local, self.remote = streams.addresses(self.stream)

    def _receiver(self) -> Callable[[], List[Any] | None]:
        recv_into = self.stream.recv_into
        reader = self.reader
        recv_buffer = reader.recv_buffer
        received_frames = reader.received_frames

        def receive() -> List[Any] | None:
            n = recv_into(recv_buffer())
            if n:
                return received_frames(n)
            reader.eof()  # FrameError when the publisher stopped mid-frame
            return None

        return receive


# ---------------------------------------------------------------------------------------------
# the protocol


class TCPROSHandler(ProtocolHandler):
    """TCPROS for a node whose TCPROS server is at ``address()`` (``(host, port)``)."""

    protocol = TCPROS

    def __init__(self, address: Callable[[], Tuple[str, int]]) -> None:
        self.address = address

    def answer(self, topic: str, offer: List[Any]) -> List[Any] | None:
        host, port = self.address()
        return [TCPROS, host, port]

    def connect(self, answer: List[Any], topic: str, buff_size: int, reuse_big: bool,
                tcp_nodelay: bool) -> Transport:
        if (len(answer) != 3 or not isinstance(answer[1], str)
                or not isinstance(answer[2], int) or isinstance(answer[2], bool)):
            raise ValueError(f"publisher returned invalid protocol choice: {answer}")
        stream = connect(answer[1], answer[2], nodelay=tcp_nodelay)
        return TCPROSReceiver(stream, topic, buff_size, reuse_big)

    def claims(self, header: Dict[str, str]) -> bool:
        return route(header) == "topic"

    def accept(self, stream: Any, header: Dict[str, str], publication: PublicationSide) -> None:
        """Answer a subscriber's header for ``publication``: the publisher's end joins the
        publication's connections, or ``Rejected`` (after the refusal was sent)."""
        refuse = None
        if publication.closed:
            refuse = f"Internal error processing topic [{publication.resolved_name}]"
        handshake = Handshake(Role.PUBLISHER, publication.header_fields(), refuse=refuse)
        sender = TCPROSSender(stream, publication.resolved_name, publication.queue_size,
                              publication.remove_connection)
        sender.negotiate(handshake, header)
        if handshake.tcp_nodelay(publication.tcp_nodelay):
            stream.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        publication.add_connection(sender)
