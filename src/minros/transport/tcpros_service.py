"""TCPROS for services: the client's end and the server's end of a service connection, on the
same stream transport as a topic's (``tcpros_base``: the stream and its addresses, the peer's
header, the counters, the header exchange):

    client -> header {service, md5sum, callerid[, persistent, probe, ...]}
    server -> header {service, type, md5sum, callerid}   (or {error} and close)
    client -> uint32 len + request            (nothing more for a probe)
    server -> uint8 ok + uint32 len + response | error string
    ... repeated while the connection is persistent

Both ends keep their stream blocking: a wait for a request or a response is one ``recv``, and
whoever ends the connection wakes a thread blocked in it by shutting the stream down (node
shutdown, an eviction). Sends never block on a peer that reads nothing for longer than a
stall timeout (``wire.sockets.send_all``), and ``stop()`` (node shutdown) ends any wait.
A server's end reads its requests under the admission of the node's server (``FrameSource``'s
guard): deadlines a trickling client cannot extend, bytes charged as they arrive.
"""

from __future__ import annotations

from typing import Any, Callable, Dict, Tuple

from minros.transport.tcpros_base import TCPROSTransport, connect, negotiate
from minros.wire import sockets, tcpros
from minros.wire.handshake import Handshake, State

__all__ = ["SEND_STALL_TIMEOUT", "ServiceClientEnd", "ServiceServerEnd", "connect_service"]

#: a send gives up on a peer that took no byte for this long (the bound topics'
#: SYNC_SEND_TIMEOUT puts on synchronous publishing). rospy's sendall waits forever; as long as
#: the peer keeps taking bytes, however slowly, a send goes on.
SEND_STALL_TIMEOUT = 60.0
#: a send waiting for a peer that reads nothing wakes up this often to notice ``stop()``
POLL = 1.0


def _never() -> bool:
    return False


class _ServiceEnd(TCPROSTransport):
    """What both ends of a service connection do: send completely, bounded."""

    def __init__(self, stream: Any, service: str, stop: Callable[[], bool] = _never,
                 buff_size: int = tcpros.DEFAULT_BUFF_SIZE,
                 stall_timeout: float | None = None) -> None:
        super().__init__(stream, service)
        self.stop = stop
        self.buff_size = buff_size
        #: None: SEND_STALL_TIMEOUT (read when sending)
        self.stall_timeout = stall_timeout
        self.bytes_sent = 0
        self.source: sockets.FrameSource | None = None

    @property
    def stat_bytes(self) -> int:
        received = self.source.reader.bytes_received if self.source is not None else 0
        return self.bytes_sent + received

    def send_all(self, data: Any) -> None:
        """Send ``data`` (bytes, or a list or tuple of buffers) completely; TransportTerminated
        at ``stop()``, for a peer gone, or one stalled for the stall timeout."""
        if data.__class__ is tuple:
            data = list(data)
        sockets.send_all(self.stream, data, pace=POLL, stop=self.stop,
                         stall_timeout=SEND_STALL_TIMEOUT if self.stall_timeout is None
                         else self.stall_timeout)
        self.bytes_sent += len(data) if data.__class__ is bytes else \
            sum(memoryview(p).nbytes for p in data)

    def _send_header(self, stream: Any, data: bytes) -> None:
        self.send_all(data)


class ServiceClientEnd(_ServiceEnd):
    """The client's end of one connection to a service: the header exchange, then one request
    and one response per :meth:`call` (many while the connection is persistent)."""

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        """Send our header and check the server's (a probe sends its header only); the stream
        blocks without a timeout afterwards (a call waits for its handler)."""
        self.header = negotiate(self.stream, handshake, send=self._send_header)
        self.stream.settimeout(None)
        self.source = sockets.FrameSource(self.stream, tcpros.FrameReader(
            buff_size=self.buff_size, ok_byte=True), stop=self.stop)

    def call(self, request: Any) -> Tuple[bool, Any] | None:
        """Send a request frame, return ``(ok, payload)`` of the response (None: the server
        closed the connection first)."""
        assert self.source is not None, "negotiate first"
        self.send_all(request)
        self.stat_msgs += 1
        reply: Tuple[bool, Any] | None = self.source.next()
        return reply

    def probe(self, fields: Dict[str, str], max_header: int) -> Dict[str, str]:
        """Send a probe header (``probe=1``, md5sum ``*``) and return the header the server
        answers with: its type and md5sum (no request follows)."""
        self.send_all(tcpros.encode_header(fields))
        header = sockets.read_header(self.stream, max_header)
        self.header = header
        return header


class ServiceServerEnd(_ServiceEnd):
    """The server's end of one client's connection, from its opening header on: requests are
    read under ``guard`` (the node server's admission of this connection)."""

    def __init__(self, stream: Any, service: str, guard: Any, buff_size: int,
                 first_chunk: int, stop: Callable[[], bool] = _never) -> None:
        super().__init__(stream, service, stop, buff_size)
        self.guard = guard
        self.first_chunk = first_chunk
        self.persistent = False

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        """Answer the client's ``opening``; afterwards ``handshake.state`` says what the
        connection is (REJECTED after the refusal was sent, CLOSED for a probe, OPEN)."""
        if opening is None:
            raise ValueError("a service server negotiates with the opening header it read")
        self.stream.settimeout(None)
        self.send_all(handshake.opening_received(opening))
        self.header = dict(opening)
        self.persistent = handshake.persistent
        if handshake.state is State.OPEN:
            self.source = sockets.FrameSource(
                self.stream, tcpros.FrameReader(buff_size=self.buff_size,
                                                first_chunk=self.first_chunk),
                stop=self.stop, guard=self.guard)

    def next_request(self, wait_until: float | None = None) -> Any:
        """The next request's frame (charged, and the connection busy once it is whole), or
        None when the client closed between requests; TransportTerminated past
        ``wait_until`` (the first byte's deadline) or at ``stop()``."""
        assert self.source is not None, "negotiate first"
        frame = self.source.next(wait_until)
        if frame is not None:
            self.stat_msgs += 1
        return frame


def connect_service(host: str, port: int, service: str, timeout: float,
                    stop: Callable[[], bool] = _never,
                    buff_size: int = tcpros.DEFAULT_BUFF_SIZE) -> ServiceClientEnd:
    """The client's end of a connection to the service at ``host:port`` (TCP_NODELAY: a call
    is latency), connected and not negotiated yet; OSError when it cannot be reached."""
    return ServiceClientEnd(connect(host, port, timeout, nodelay=True), service, stop,
                            buff_size)
