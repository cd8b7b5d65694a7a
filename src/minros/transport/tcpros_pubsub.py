"""TCPROS for topics: the publisher's end, the subscriber's end, and the protocol handler.

The publisher's end (:class:`TCPROSSender`) is the queued sender of ``sender`` with TCPROS's
wire: the frames themselves, many small ones joined into one send when they had to wait, a big
one sent alone so that the queue keeps the newest. A frame goes out in one non-blocking send
in the publishing thread when the socket is idle, the usual case.

The subscriber's end (:class:`TCPROSReceiver`) receives into a preallocated buffer and cuts
frames with ``minros.wire.tcpros.FrameReader`` (a large frame lands in a buffer of its own,
zero-copy). :class:`TCPROSHandler` is TCPROS as a :class:`~minros.transport.base.ProtocolHandler`:
requestTopic's answer is the node's TCPROS server address, and the server hands it every
inbound topic connection that arrives on its TCP socket.
"""

from __future__ import annotations

import socket
from typing import Any, Callable, Dict, List, Tuple

from minros.transport import streams
from minros.transport.base import Frame, ProtocolHandler, PublicationSide, Transport
from minros.transport.sender import QueuedSender, _yield_gil
from minros.transport.sendqueue import (  # noqa: F401 - the numbers of TCPROS's queue
    BACKOFF_MAX,
    BACKOFF_MIN,
    BACKOFF_RATE,
    SYNC_SEND_TIMEOUT,
)
from minros.transport.streams import MSG_DONTWAIT
from minros.transport.tcpros_base import TCPROS, TCPROSTransport, connect, negotiate, tcpros_info
from minros.wire import tcpros
from minros.wire.handshake import Handshake, Role, route

__all__ = ["SYNC_SEND_TIMEOUT", "TCPROSHandler", "TCPROSReceiver", "TCPROSSender"]


# ---------------------------------------------------------------------------------------------
# the publisher's end


class TCPROSSender(QueuedSender):
    """The publisher's end of one subscriber's TCPROS connection.

    ``on_close(self)`` runs once, in the connection's watcher thread, when the connection
    fails or the subscriber leaves (not when :meth:`close` is called)."""

    protocol = TCPROS

    def info(self) -> str:
        return tcpros_info(self.local, self.remote, self.fileno)

    def send(self, frame: Frame) -> None:
        """Send one frame: queued publishers do not wait for the subscriber (the frame waits
        in the queue for the writer thread; a full queue makes a big frame wait a moment for
        room), queue_size=None ones send it all before returning, as rospy does."""
        if self.done:
            return
        with self.lock:
            if not self.out and not self.busy and not self.queue.items:
                # the socket is idle: hand the bytes to the kernel now, without blocking
                if frame.__class__ is not bytes:  # a big frame: what the kernel takes
                    self.out, self.out_count = list(frame), 1
                    self._pump()  # the writer is told of the rest
                    if self.sync:
                        self._drain()
                    return
                try:
                    sent = self.stream.send(frame, MSG_DONTWAIT)
                except BlockingIOError:
                    sent = 0
                except OSError as exc:
                    self._fail(exc)
                    return
                self.bytes_sent += sent
                if sent == len(frame):  # all of it in one call: the usual case
                    self.stat_msgs += 1
                    return
                self.out, self.out_count = [memoryview(frame)[sent:]], 1
                if self.sync:
                    self._drain()
                else:
                    self.cond.notify()  # the writer sends the rest
                return
            queue = self.queue
            if queue.limit and len(queue.items) >= queue.limit:  # full: back off, drop the oldest
                if not self._enqueue(frame, frame):
                    return
            else:  # room: the hot path of a flood, one append
                queue.items.append(frame)
            if self.sync:
                self._drain()
                return
            if not self.busy:  # a busy writer takes it without being told (and a notify
                if self.out:  # costs a microsecond even with no one waiting)
                    self.cond.notify()
                else:  # the writer sent everything while we backed off: nobody would
                    self._pump()  # move the queue into out (a flood stalled for good)
        # The writer thread is behind: let it have the GIL now rather than after the
        # interpreter's switch interval (5 ms), or a publishing loop starves it.
        _yield_gil()

    def _next_out(self) -> bool:
        items = self.queue.items
        if not items:
            return False
        first = items.popleft()
        if first.__class__ is not bytes:  # a big frame: alone, so that the queue keeps the newest
            self.out, self.out_count = list(first), 1
        elif items and items[0].__class__ is bytes:  # small frames: all of them, in one send
            batch = [first]
            while items and items[0].__class__ is bytes:
                batch.append(items.popleft())
            self.out, self.out_count = [b"".join(batch)], len(batch)
        else:
            self.out, self.out_count = [first], 1
        return True


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

    def claims(self, header: Dict[str, str], listener: str) -> bool:
        return listener == TCPROS and route(header) == "topic"

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
