"""TCPROS over a stream: the header exchange run on a socket, and what every TCPROS end keeps.

:func:`negotiate` is the one place a connection-header exchange touches a socket: it moves the
bytes that :class:`minros.wire.handshake.Handshake` decides, for topics and services, on
either side. :class:`TCPROSTransport` is the common part of a topic connection's two ends
(``tcpros_pubsub``): the stream, the peer's header, the counters, getBusInfo's line.
"""

from __future__ import annotations

import socket
from typing import Any, Callable, Dict

from minros.transport.streams import StreamTransport
from minros.wire import sockets, trace
from minros.wire.handshake import Handshake, Rejected, State

__all__ = ["TCPROS", "TCPROSTransport", "connect", "negotiate", "tcpros_info"]

#: the protocol's name in requestTopic
TCPROS = "TCPROS"
#: seconds to connect to a publisher or service, and then to receive its header
CONNECT_TIMEOUT = 10.0


def negotiate(stream: Any, handshake: Handshake, opening: Dict[str, str] | None = None, *,
              send: Callable[[Any, bytes], None] | None = None,
              deadline: float | None = None) -> Dict[str, str]:
    """Run ``handshake`` over ``stream`` and return the peer's header.

    The initiator sends its opening and reads the answer (by ``deadline``, default the
    stream's timeout from now); the acceptor answers ``opening``, the header it read already.
    ``send(stream, data)`` sends completely (default ``stream.sendall``). Raises ``Rejected``
    when the exchange refused the connection (the acceptor's refusal is sent first),
    ``HeaderError`` or ``OSError`` when the peer fails."""
    if send is None:
        send = _sendall
    if handshake.role.initiates:
        send(stream, handshake.opening())
        if handshake.state is State.CLOSED:  # a probe: nothing comes back that matters
            return {}
        header = sockets.read_header(stream, deadline=deadline)
        handshake.reply_received(header)
        return header
    if opening is None:
        raise ValueError("an acceptor negotiates with the opening header it received")
    send(stream, handshake.opening_received(opening))
    if handshake.state is State.REJECTED:
        raise Rejected(handshake.error or "connection refused")
    return dict(opening)


def _sendall(stream: Any, data: bytes) -> None:
    stream.sendall(data)


def connect(host: str, port: int, timeout: float = CONNECT_TIMEOUT,
            nodelay: bool = False) -> socket.socket:
    """A TCP connection to a publisher or service (every address of ``host`` is tried:
    localhost may be ::1), in blocking mode with ``timeout``; traced when tracing is on."""
    sock = socket.create_connection((host, port), timeout=timeout)
    if nodelay:
        try:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        except OSError:  # not fatal: only latency
            pass
    traced: socket.socket = trace.watch(sock, "connect")
    return traced


class TCPROSTransport(StreamTransport):
    """What both ends of a TCPROS topic connection keep: the stream and its addresses, the
    peer's header, the counters."""

    protocol = TCPROS

    def info(self) -> str:
        return tcpros_info(self.local, self.remote, self.fileno)


def tcpros_info(local: Any, remote: Any, fileno: int) -> str:
    """getBusInfo's line for a TCPROS connection, as rospy writes it."""
    return (f"TCPROS connection on port {local[1]} to [{remote[0]}:{remote[1]}"
            f" on socket {fileno}]")
