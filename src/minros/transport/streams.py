"""The byte stream a TCPROS transport runs over: a connected socket, or anything with its methods.

The transports call the socket methods themselves (each one a C call: the hot path pays for
no wrapper), so the seam is the subset of ``socket.socket`` they use, written down as
:class:`Stream`; :class:`StreamTransport` is what every transport over a stream keeps. Tests hand them an in-memory stream with the same methods
(``tests/memstream.py``, as httpcore's MockStream or goroslib's ``io.ReadWriter``) to drive a
slow subscriber or a half-sent frame without a real connection; such a stream, having no file
descriptor to poll, also provides ``wait_writable(timeout)`` and ``wait_readable(timeout)``.
"""

from __future__ import annotations

import select
from typing import Any, Dict, Iterable, Protocol, Tuple

from minros.transport.base import Transport, next_connection_id
from minros.wire import sockets
from minros.wire.sockets import MSG_DONTWAIT

__all__ = ["MSG_DONTWAIT", "Stream", "StreamTransport", "addresses", "wait_readable",
           "wait_writable"]


class Stream(Protocol):
    """The part of a connected ``socket.socket`` a transport uses."""

    def send(self, data: Any, flags: int = ..., /) -> int: ...
    def sendmsg(self, buffers: Iterable[Any], ancdata: Iterable[Any] = ..., flags: int = ...,
                /) -> int: ...
    def sendall(self, data: Any, flags: int = ..., /) -> None: ...
    def recv(self, bufsize: int, flags: int = ..., /) -> bytes: ...
    def recv_into(self, buffer: Any, nbytes: int = ..., flags: int = ..., /) -> int: ...
    def shutdown(self, how: int, /) -> None: ...
    def close(self) -> None: ...
    def fileno(self) -> int: ...
    def getsockname(self) -> Any: ...
    def getpeername(self) -> Any: ...
    def settimeout(self, value: float | None, /) -> None: ...
    def gettimeout(self) -> float | None: ...
    def setsockopt(self, level: int, option: int, value: int, /) -> None: ...


def wait_writable(stream: Any, timeout: float) -> bool:
    """Wait up to ``timeout`` seconds until ``stream`` takes bytes again; True if it does."""
    wait = getattr(stream, "wait_writable", None)
    if wait is not None:
        return bool(wait(timeout))
    poller = select.poll()  # not select(): descriptors may be above FD_SETSIZE
    poller.register(stream, select.POLLOUT)
    return bool(poller.poll(timeout * 1000))


def wait_readable(stream: Any, timeout: float) -> bool:
    """Wait up to ``timeout`` seconds until ``stream`` has bytes (or its end) to read."""
    wait = getattr(stream, "wait_readable", None)
    if wait is not None:
        return bool(wait(timeout))
    poller = select.poll()
    poller.register(stream, select.POLLIN)
    return bool(poller.poll(timeout * 1000))


def addresses(stream: Any) -> Tuple[Any, Any]:
    """``(local, remote)`` addresses of a connected stream (``("", 0)`` when it has none)."""
    try:
        return stream.getsockname(), stream.getpeername()
    except OSError:
        return ("", 0), ("", 0)


class StreamTransport(Transport):
    """What both ends of a connection over a stream keep, whatever the protocol: the stream and
    its addresses, the topic, the peer's header, the counters."""

    def __init__(self, stream: Any, topic: str) -> None:
        self.id = next_connection_id()
        self.stream = stream
        self.topic = topic
        self.header: Dict[str, str] = {}
        self.stat_msgs = 0
        self.done = False
        self.local, self.remote = addresses(stream)
        try:
            self.fileno = stream.fileno()
        except OSError:
            self.fileno = -1

    @property
    def callerid(self) -> str:
        """The peer's caller id, from its header."""
        return self.header.get("callerid", "")

    def close(self) -> None:
        self.done = True
        sockets.close(self.stream)
