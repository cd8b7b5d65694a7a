"""The socket chores of TCPROS, written once: read one connection header, send a list of
buffers completely, pull frames one at a time, close a socket.

The protocol itself (header codec, framing) is :mod:`minros.wire.tcpros`, pure; this module
only moves its bytes. Callers pass ``stop``, a function that says when to give up waiting
(node shutdown), so the wire layer knows nothing of nodes. The topic hot path
(:mod:`minros.client.topics`) keeps its own non-blocking sends, tuned for latency.
"""

from __future__ import annotations

import collections
import socket
import struct
import time
from typing import Any, Callable, Dict, Optional

from minros.exceptions import TransportTerminated
from minros.wire import tcpros

__all__ = ["FrameSource", "close", "read_header", "send_all"]

#: buffers handed to one sendmsg call (Linux takes up to IOV_MAX = 1024)
_MAX_IOV = 512
_HAS_SENDMSG = hasattr(socket.socket, "sendmsg")


def _never() -> bool:
    return False


def close(sock: Optional[socket.socket]) -> None:
    """Shut a socket down in both directions (waking a thread blocked on it), then close it."""
    if sock is None:
        return
    try:
        sock.shutdown(socket.SHUT_RDWR)
    except OSError:
        pass
    try:
        sock.close()
    except OSError:
        pass


def _recv_exact(sock: socket.socket, size: int) -> bytes:
    buf = bytearray(size)
    view = memoryview(buf)
    got = 0
    while got < size:
        try:
            n = sock.recv_into(view[got:])
        except socket.timeout:
            raise tcpros.HeaderError("timed out waiting for the connection header") from None
        except OSError as exc:
            raise tcpros.HeaderError(f"unable to receive the connection header: {exc}") from None
        if not n:
            raise tcpros.HeaderError(f"connection closed after {got} of {size} header bytes")
        got += n
    return bytes(buf)


def read_header(sock: socket.socket, max_size: int = tcpros.DEFAULT_MAX_HEADER) -> Dict[str, str]:
    """Read exactly one connection header from ``sock`` (nothing beyond it), for either side of
    a topic or service handshake. The socket's timeout bounds every read; every failure is a
    HeaderError naming it."""
    (size,) = struct.unpack("<I", _recv_exact(sock, 4))
    if size > max_size:
        raise tcpros.HeaderError(f"connection header of {size} bytes exceeds the limit of {max_size}")
    return tcpros.decode_header(_recv_exact(sock, size))


def send_all(sock: socket.socket, data: Any, *, stall_timeout: float,
             stop: Callable[[], bool] = _never) -> None:
    """Send ``data`` (bytes, or a list of buffers sent in order) completely.

    The socket's timeout only paces the waiting, so that ``stop()`` is noticed: ``sendall``
    would apply it to the whole transfer and fail a big message to a slow reader. The send
    goes on while the peer takes bytes and raises TransportTerminated when ``stop()`` says so,
    the peer is gone, or the peer took nothing for ``stall_timeout`` seconds.
    """
    if not isinstance(data, list):
        data = [data]
    parts = [memoryview(part) for part in data if len(part)]  # an empty one would never go
    first = 0  # parts[first:] are unsent; parts[first] may have been sliced
    deadline = time.monotonic() + stall_timeout
    while first < len(parts):
        if stop():
            raise TransportTerminated("node shutdown")
        try:
            if _HAS_SENDMSG and first + 1 < len(parts):
                sent = sock.sendmsg(parts[first:first + _MAX_IOV])
            else:
                sent = sock.send(parts[first])
        except socket.timeout:  # not writable for one socket timeout
            if time.monotonic() >= deadline:
                raise TransportTerminated(f"peer took no data for {stall_timeout:g} s") from None
            continue
        except OSError as exc:
            raise TransportTerminated(f"unable to send data: {exc}") from None
        if sent:
            deadline = time.monotonic() + stall_timeout
        while sent:
            size = parts[first].nbytes
            if sent < size:
                parts[first] = parts[first][sent:]
                break
            sent -= size
            first += 1


class FrameSource:
    """Frames from one socket, one at a time (a FrameReader may parse several per recv)."""

    def __init__(self, sock: socket.socket, reader: tcpros.FrameReader,
                 stop: Callable[[], bool] = _never) -> None:
        self.sock = sock
        self.reader = reader
        self.stop = stop
        self.pending: collections.deque = collections.deque()

    def next(self) -> Any:
        """The next frame; None if the peer closed cleanly between frames. A socket timeout
        only paces the check of ``stop()``."""
        reader = self.reader
        while not self.pending:
            target = reader.recv_buffer()
            while True:
                try:
                    n = self.sock.recv_into(target)
                    break
                except socket.timeout:
                    if self.stop():
                        raise TransportTerminated("node shutdown") from None
                except OSError as exc:
                    raise TransportTerminated(f"unable to receive data from sender: {exc}") from None
            # release the view now: the reader grows a big frame's buffer in the next
            # recv_buffer(), which a live export of it would make fail (BufferError)
            del target
            if not n:
                reader.eof()  # FrameError (a TransportException) when cut mid-frame
                return None
            reader.received(n)
            self.pending.extend(reader.frames())
        return self.pending.popleft()
