"""The socket chores of TCPROS, written once: read one connection header, send a list of
buffers completely, pull frames one at a time, close a socket.

The protocol itself (header codec, framing) is :mod:`minros.wire.tcpros`, pure; this module
only moves its bytes. Callers pass ``stop``, a function that says when to give up waiting
(node shutdown), so the wire layer knows nothing of nodes. The topic hot path
(:mod:`minros.client.topics`) keeps its own non-blocking sends, tuned for latency.
"""

from __future__ import annotations

import collections
import select
import socket
import struct
import time
from typing import Any, Callable, Deque, Dict, Optional, Tuple

from minros.exceptions import TransportTerminated
from minros.wire import tcpros

__all__ = ["FrameSource", "close", "peer_credentials", "peer_pid", "read_header", "send_all"]

#: the most of a connection header received at once
_HEADER_CHUNK = 65536
#: buffers handed to one sendmsg call (Linux takes up to IOV_MAX = 1024)
_MAX_IOV = 512
_HAS_SENDMSG = hasattr(socket.socket, "sendmsg")
#: a send that takes what fits and never blocks
MSG_DONTWAIT: int = getattr(socket, "MSG_DONTWAIT", 0)
_CREDS = struct.Struct("3i")


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


def peer_credentials(sock: Any) -> Tuple[int, int, int] | None:
    """``(pid, uid, gid)`` of the process at the other end of a Unix socket (SO_PEERCRED), or
    None (another kind of stream)."""
    try:
        creds = sock.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, _CREDS.size)
        pid, uid, gid = _CREDS.unpack(creds)
    except (OSError, AttributeError, struct.error):
        return None
    return int(pid), int(uid), int(gid)


def peer_pid(sock: Any) -> int:
    """The pid of the process at the other end of a Unix socket (0 when unknown)."""
    creds = peer_credentials(sock)
    return creds[0] if creds is not None else 0


def _recv_exact(sock: socket.socket, size: int, deadline: float | None,
                charge: Callable[[int], Any] | None) -> bytes:
    """``size`` bytes, kept as they arrive (a length a peer only announces costs nothing),
    before ``deadline`` however slowly they trickle in."""
    buf = bytearray()
    while len(buf) < size:
        if deadline is not None:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise tcpros.HeaderError("timed out waiting for the connection header")
            sock.settimeout(remaining)
        try:
            chunk = sock.recv(min(size - len(buf), _HEADER_CHUNK))
        except socket.timeout:
            raise tcpros.HeaderError("timed out waiting for the connection header") from None
        except OSError as exc:
            raise tcpros.HeaderError(f"unable to receive the connection header: {exc}") from None
        if not chunk:
            raise tcpros.HeaderError(f"connection closed after {len(buf)} of {size} header bytes")
        if charge is not None:
            charge(len(chunk))
        buf += chunk
    return bytes(buf)


def read_header(sock: socket.socket, max_size: int = tcpros.DEFAULT_MAX_HEADER, *,
                deadline: float | None = None,
                charge: Callable[[int], Any] | None = None) -> Dict[str, str]:
    """Read exactly one connection header from ``sock`` (nothing beyond it), for either side of
    a topic or service handshake. The whole header must arrive before ``deadline``
    (``time.monotonic()``; default: the socket's timeout from now), so a peer trickling it
    cannot hold the caller longer; ``charge(n)`` is told of every ``n`` bytes received (and
    may raise to stop). Every failure of the peer is a HeaderError naming it."""
    if deadline is None:
        timeout = sock.gettimeout()
        deadline = None if timeout is None else time.monotonic() + timeout
    (size,) = struct.unpack("<I", _recv_exact(sock, 4, deadline, charge))
    if size > max_size:
        raise tcpros.HeaderError(f"connection header of {size} bytes exceeds the limit of {max_size}")
    return tcpros.decode_header(_recv_exact(sock, size, deadline, charge))


def _wait_writable(sock: Any, timeout: float) -> None:
    """Wait up to ``timeout`` seconds for ``sock`` to take bytes again."""
    wait = getattr(sock, "wait_writable", None)  # an in-memory test stream
    if wait is not None:
        wait(timeout)
        return
    poller = select.poll()  # not select(): descriptors may be above FD_SETSIZE
    poller.register(sock, select.POLLOUT)
    poller.poll(max(timeout, 0.0) * 1000)


def send_all(sock: socket.socket, data: Any, *, stall_timeout: float,
             stop: Callable[[], bool] = _never, pace: float = 1.0) -> None:
    """Send ``data`` (bytes, or a list of buffers sent in order) completely.

    Every send is non-blocking, so the usual small message costs one system call and the
    socket may be a blocking one (a closer wakes a thread blocked in it by shutting it down).
    Only when the kernel takes nothing does the sender wait for the socket to be writable,
    ``pace`` seconds at most at a time, so that ``stop()`` is noticed: the send goes on while
    the peer takes bytes and raises TransportTerminated when ``stop()`` says so, the peer is
    gone, or the peer took nothing for ``stall_timeout`` seconds. (A socket with a timeout
    paces itself by it too: ``sendall`` would apply it to the whole transfer and fail a big
    message to a slow reader.)
    """
    if data.__class__ is bytes:
        try:  # the usual case: one small frame, taken whole by the kernel
            sent = sock.send(data, MSG_DONTWAIT)
        except (BlockingIOError, socket.timeout):
            sent = 0
        except OSError as exc:
            raise TransportTerminated(f"unable to send data: {exc}") from None
        if sent == len(data):
            return
        data = [memoryview(data)[sent:]]
    elif not isinstance(data, list):
        data = [data]
    parts = [memoryview(part) for part in data if len(part)]  # an empty one would never go
    first = 0  # parts[first:] are unsent; parts[first] may have been sliced
    deadline = time.monotonic() + stall_timeout
    while first < len(parts):
        if stop():
            raise TransportTerminated("node shutdown")
        try:
            if _HAS_SENDMSG and first + 1 < len(parts):
                sent = sock.sendmsg(parts[first:first + _MAX_IOV], (), MSG_DONTWAIT)
            else:
                sent = sock.send(parts[first], MSG_DONTWAIT)
        except (BlockingIOError, socket.timeout):  # not writable (for one socket timeout)
            sent = 0
        except OSError as exc:
            raise TransportTerminated(f"unable to send data: {exc}") from None
        now = time.monotonic()
        if not sent:
            if now >= deadline:
                raise TransportTerminated(f"peer took no data for {stall_timeout:g} s")
            _wait_writable(sock, min(pace, deadline - now))
            continue
        deadline = now + stall_timeout
        while sent:
            size = parts[first].nbytes
            if sent < size:
                parts[first] = parts[first][sent:]
                break
            sent -= size
            first += 1


class FrameSource:
    """Frames from one socket, one at a time (a FrameReader may parse several per recv).

    With a ``guard`` (a :class:`minros.wire.admission.Connection`, on a server) frames are read
    under the admission policy: their bytes are charged as they arrive, once a frame's first
    byte is in the whole frame must arrive by a deadline fixed from its announced length,
    however slowly the peer trickles it, and a frame handed out is being served (the guard is
    busy: charged and busy in one call when the frame came whole, the usual case).

    A blocking socket (no timeout) waits in ``recv`` itself, one system call per frame; whoever
    ends the connection wakes it by shutting the socket down. A socket timeout paces checks of
    ``stop()``, and deadlines set a timeout for as long as they apply.
    """

    def __init__(self, sock: socket.socket, reader: tcpros.FrameReader,
                 stop: Callable[[], bool] = _never, guard: Any = None) -> None:
        self.sock = sock
        self.reader = reader
        self.stop = stop
        self.guard = guard
        self.pending: Deque[Any] = collections.deque()
        self._poll = sock.gettimeout()  # paces the checks of stop()
        self._timeout = self._poll  # the socket's timeout now (settimeout is a system call)
        self._started: float | None = None  # when the frame in progress began to arrive

    def next(self, wait_until: float | None = None) -> Any:
        """The next frame; None if the peer closed cleanly between frames. A socket timeout
        only paces the check of ``stop()``. ``wait_until`` (``time.monotonic()``, with a
        guard) bounds the wait for a frame's first byte: TransportTerminated after it."""
        pending = self.pending
        guard = self.guard
        if pending:  # a frame that came with an earlier one
            if guard is not None:
                guard.busy()
            return pending.popleft()
        reader = self.reader
        recv_into = self.sock.recv_into
        while not pending:
            target = reader.recv_buffer()
            while True:
                if guard is not None and (wait_until is not None or self._started is not None
                                          or self._timeout != self._poll):
                    self._pace(wait_until)
                try:
                    n = recv_into(target)
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
            frames = reader.received_frames(n)
            if guard is not None:
                # the policy counts a request as reading from its first bytes, and as served
                # once it is whole
                guard.charge(n, bool(frames))
                if frames or self._started is None:
                    self._started = time.monotonic() if reader.pending() else None
            pending.extend(frames)
        return pending.popleft()

    def _pace(self, wait_until: float | None) -> None:
        """Before a guarded recv: fail past the deadline, else wait no longer than it."""
        if self._started is None:
            deadline = wait_until
            what = "no request arrived"
        else:
            deadline = self._started + self.guard.limits.transfer_time(self.reader.announced() or 0)
            what = "the request did not arrive"
        if deadline is None:
            if self._timeout != self._poll:
                self.sock.settimeout(self._poll)
                self._timeout = self._poll
            return
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise TransportTerminated(f"{what} within the deadline")
        self._timeout = remaining if self._poll is None else min(self._poll, remaining)
        self.sock.settimeout(self._timeout)
