"""An in-memory, socket-like byte stream pair for transport tests (httpcore's MockStream,
goroslib's io.ReadWriter): the methods of ``minros.transport.streams.Stream``, a bounded buffer
per direction so a test can make a subscriber slow or leave a frame half-sent, and no file
descriptor (``wait_writable``/``wait_readable`` instead of poll). File descriptors passed with
``sendmsg`` (SCM_RIGHTS, as MINROSSHM's segments travel) arrive with the byte they were sent
with, duplicated, in ``recvmsg_into``'s ancillary data.

    pub_end, sub_end = MemoryStream.pair(capacity=4096)
"""

from __future__ import annotations

import os
import socket
import struct
import threading
import time
from typing import Any, Iterable, Tuple

from minros.transport.streams import MSG_DONTWAIT


class MemoryStream:
    """One end of a connected pair. ``capacity`` bounds the bytes in flight each way."""

    def __init__(self, cond: threading.Condition, capacity: int, name: str) -> None:
        self._cond = cond
        self.capacity = capacity
        self.name = name
        self.inbox = bytearray()  # bytes sent by the peer, not read yet
        self.peer: MemoryStream = self
        self.read_shut = False  # no more reading here
        self.write_shut = False  # no more writing here (the peer reads the end)
        self.closed = False
        self._timeout: float | None = None
        self.sent_total = 0
        #: descriptors sent by the peer: [offset in inbox, fd], in order
        self.fds: list = []

    @classmethod
    def pair(cls, capacity: int = 1 << 20) -> Tuple[MemoryStream, MemoryStream]:
        cond = threading.Condition()
        a, b = cls(cond, capacity, "a"), cls(cond, capacity, "b")
        a.peer, b.peer = b, a
        return a, b

    # -- waiting ------------------------------------------------------------------------------

    def _wait(self, ready: Any, flags: int = 0) -> None:
        """Wait (lock held) until ``ready()``; BlockingIOError for a non-blocking call,
        socket.timeout after the stream's timeout."""
        if ready():
            return
        if flags & MSG_DONTWAIT or self._timeout == 0:
            raise BlockingIOError(11, "Resource temporarily unavailable")
        deadline = None if self._timeout is None else time.monotonic() + self._timeout
        while not ready():
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                raise socket.timeout("timed out")
            self._cond.wait(remaining)

    def _room(self) -> int:
        return self.capacity - len(self.peer.inbox)

    def _broken(self) -> bool:
        return self.closed or self.write_shut or self.peer.closed or self.peer.read_shut

    # -- sending ------------------------------------------------------------------------------

    def sendmsg(self, buffers: Iterable[Any], ancdata: Iterable[Any] = (), flags: int = 0) -> int:
        data = b"".join(bytes(memoryview(b)) for b in buffers)
        fds = []
        for level, kind, raw in ancdata:
            if level == socket.SOL_SOCKET and kind == socket.SCM_RIGHTS:
                fds.extend(struct.unpack(f"{len(raw) // 4}i", raw))
        with self._cond:
            at = len(self.peer.inbox)
            sent = self.send(data, flags)
            if sent and fds:  # they go with the first byte, as over a Unix socket
                self.peer.fds.extend([at, os.dup(fd)] for fd in fds)
            return sent

    def send(self, data: Any, flags: int = 0) -> int:
        view = memoryview(data).cast("B")
        with self._cond:
            self._wait(lambda: self._broken() or self._room() > 0 or not len(view), flags)
            if self._broken():
                raise BrokenPipeError(32, "Broken pipe")
            n = min(self._room(), len(view))
            self.peer.inbox += view[:n]
            self.sent_total += n
            self._cond.notify_all()
            return n

    def sendall(self, data: Any, flags: int = 0) -> None:
        view = memoryview(data).cast("B")
        while len(view):
            view = view[self.send(view, flags):]

    def wait_writable(self, timeout: float) -> bool:
        with self._cond:
            self._cond.wait_for(lambda: self._broken() or self._room() > 0, timeout)
            return self._room() > 0

    # -- receiving ----------------------------------------------------------------------------

    def _eof(self) -> bool:
        return self.closed or self.read_shut or self.peer.write_shut or self.peer.closed

    def recv(self, bufsize: int, flags: int = 0) -> bytes:
        with self._cond:
            self._wait(lambda: bool(self.inbox) or self._eof(), flags)
            if self.closed or self.read_shut:
                return b""
            data = bytes(self.inbox[:bufsize])
            del self.inbox[:len(data)]
            self._cond.notify_all()
            return data

    def recv_into(self, buffer: Any, nbytes: int = 0, flags: int = 0) -> int:
        target = memoryview(buffer).cast("B")
        data = self.recv(nbytes or len(target), flags)
        target[:len(data)] = data
        return len(data)

    def recvmsg_into(self, buffers: Any, ancbufsize: int = 0, flags: int = 0) -> tuple:
        """Into the first buffer; the descriptors sent with the bytes received come along."""
        target = memoryview(buffers[0]).cast("B")
        with self._cond:
            self._wait(lambda: bool(self.inbox) or self._eof(), flags)
            if self.closed or self.read_shut:
                return 0, [], 0, None
            n = min(len(target), len(self.inbox))
            if self.fds:  # a read stops before the next descriptor's byte, as the kernel's
                later = [at for at, _ in self.fds if at > 0]
                n = min([n, *later])
            target[:n] = self.inbox[:n]
            del self.inbox[:n]
            fds = [fd for at, fd in self.fds if at < n]
            self.fds = [[at - n, fd] for at, fd in self.fds if at >= n]
            self._cond.notify_all()
        ancdata = [(socket.SOL_SOCKET, socket.SCM_RIGHTS, struct.pack(f"{len(fds)}i", *fds))] \
            if fds else []
        return n, ancdata, 0, None

    def wait_readable(self, timeout: float) -> bool:
        with self._cond:
            return self._cond.wait_for(lambda: bool(self.inbox) or self._eof(), timeout)

    # -- the rest of a socket -----------------------------------------------------------------

    def shutdown(self, how: int) -> None:
        with self._cond:
            if how in (socket.SHUT_RD, socket.SHUT_RDWR):
                self.read_shut = True
            if how in (socket.SHUT_WR, socket.SHUT_RDWR):
                self.write_shut = True
            self._cond.notify_all()

    def close(self) -> None:
        with self._cond:
            self.closed = True
            fds, self.fds = self.fds, []
            self._cond.notify_all()
        for _, fd in fds:
            os.close(fd)

    def fileno(self) -> int:
        return -1

    def getsockname(self) -> Tuple[str, int]:
        return ("memory", 1 if self.name == "a" else 2)

    def getpeername(self) -> Tuple[str, int]:
        return self.peer.getsockname()

    def settimeout(self, value: float | None) -> None:
        self._timeout = value

    def gettimeout(self) -> float | None:
        return self._timeout

    def setsockopt(self, *args: Any) -> None:
        pass

    def setblocking(self, flag: bool) -> None:
        self._timeout = None if flag else 0.0

    def pending(self) -> int:
        """Bytes waiting for this end to read."""
        with self._cond:
            return len(self.inbox)

    def wait_pending(self, predicate: Any, timeout: float = 5.0) -> bool:
        """Wait until ``predicate(len(self.inbox))`` (the test's event, no polling)."""
        with self._cond:
            return self._cond.wait_for(lambda: predicate(len(self.inbox)), timeout)

    def wait_sent(self, predicate: Any, timeout: float = 5.0) -> bool:
        """Wait until ``predicate(bytes this end has sent)``."""
        with self._cond:
            return self._cond.wait_for(lambda: predicate(self.sent_total), timeout)
