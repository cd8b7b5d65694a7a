"""The publisher's end of a stream connection, written once for every stream transport
(TCPROS's ``TCPROSSender``, MINROSSHM's ``ShmSender``): the queue, the writer thread, the
watcher thread, the failure path.

Latency stays at raw-socket level without making a queued publisher wait for a slow
subscriber: what may go now is sent by the publishing thread itself, in one non-blocking call
(:meth:`QueuedSender._pump`); only what the kernel did not take waits, as ``out`` (the unsent
rest of the record being sent, never dropped) and the queue behind it (``sendqueue``: bounded,
oldest dropped, a full queue makes a big frame wait a moment for room), for the connection's
writer thread (``minros-pub:<topic>``), which sends ``out`` blocking and then pumps again. A
``queue_size=None`` publisher has no writer: it hands everything over before ``send`` returns
(:meth:`QueuedSender._drain`), and gives up on a subscriber that takes nothing for
SYNC_SEND_TIMEOUT seconds.

The watcher thread (``minros-pub-watch:<topic>``) reads what the subscriber sends: nothing over
TCPROS (a readable socket means it left), the slots it gives back over MINROSSHM. It is also
the one that tells the publication of a connection that failed (``on_close``), whichever thread
found the failure: the failing thread closes the stream, which wakes the watcher. So the
publication's lock, taken before this one, is never taken under it, and a failure creates no
thread (Python 3.12 refuses new threads at interpreter shutdown).

A transport says only what goes on its wire: ``send`` (its fast path, then the core's queue),
:meth:`QueuedSender._next_out` moves the next records from the queue into ``out``,
:meth:`QueuedSender._transmit` sends them, :meth:`QueuedSender._watch` reads the subscriber.
"""

from __future__ import annotations

import logging
import os
import socket
import struct
import threading
import time
from typing import Any, Callable, Dict, List, Tuple

from minros.transport import sendqueue
from minros.transport.base import Frame, Transport
from minros.transport.sendqueue import SendQueue
from minros.transport.streams import MSG_DONTWAIT, StreamTransport, wait_writable
from minros.transport.tcpros_base import negotiate
from minros.wire import sockets
from minros.wire.handshake import Handshake

__all__ = ["QueuedSender", "frame_size"]

_logger = logging.getLogger("minros.transport")
_FD = struct.Struct("i")


def frame_size(frame: Frame) -> int:
    """The bytes of a frame (its length prefix included)."""
    return len(frame) if frame.__class__ is bytes else sum(map(len, frame))


def _yield_gil() -> None:
    time.sleep(0)


class QueuedSender(StreamTransport):
    """The publisher's end of one subscriber's connection over a stream.

    ``on_close(self)`` runs once, in the watcher thread, when the connection fails or the
    subscriber leaves (not when :meth:`close` is called). Lock order: the publication's lock,
    then ``lock`` (``cond`` and ``space`` share it)."""

    #: errors that only mean the subscriber went away (no log line)
    QUIET: Tuple[type, ...] = (BrokenPipeError, ConnectionResetError)

    def __init__(self, stream: Any, topic: str, queue_size: int | None,
                 on_close: Callable[[Transport], Any]) -> None:
        super().__init__(stream, topic)
        self.bytes_sent = 0
        self.queue_size = queue_size
        self.sync = queue_size is None
        self.queue = SendQueue(queue_size)
        self.out: List[Any] = []  # the unsent rest of what is being sent: never dropped
        self.out_count = 0  # the messages in out
        self.out_fd = -1  # a descriptor to pass with out's first byte (SCM_RIGHTS)
        #: records to send before the queue, with the descriptor each carries (shared memory's
        #: SEGM and FALL; none over TCPROS)
        self.control: List[Tuple[bytes, int]] = []
        #: why the transport failed while the connection lives on ("": it did not)
        self.failed = ""
        self.lock = threading.Lock()  # C-level `with` on the hot path; the conditions share it
        self.cond = threading.Condition(self.lock)  # the writer waits here for out
        self.space = threading.Condition(self.lock)  # a publisher, for room in a full queue
        self.room_wanted = 0  # publishers waiting on space
        self.busy = False  # the writer is sending out, without the lock
        self.on_close = on_close
        #: None, or called (with the lock) with each item the full queue dropped unsent
        self.on_drop: Callable[[Any], None] | None = None
        self.ended = False  # failed, or the subscriber left: on_close is due
        self.closing = False  # close() was called

    @property
    def stat_bytes(self) -> int:
        return self.bytes_sent

    @property
    def endpoint_id(self) -> str:
        """rospy's name for the subscriber's caller id."""
        return self.callerid

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        """Answer the subscriber's ``opening`` header; once open, the connection's threads
        start (a writer unless synchronous, and the watcher)."""
        self.header = negotiate(self.stream, handshake, opening)
        if not self.sync:
            threading.Thread(target=self._writer, daemon=True,
                             name=f"minros-pub:{self.topic}").start()
        threading.Thread(target=self._watcher, daemon=True,
                         name=f"minros-pub-watch:{self.topic}").start()

    # -- what a transport provides -------------------------------------------------------------

    def _next_out(self) -> bool:
        """With the lock: move what is to go next from the queue into ``out`` (and
        ``out_count``); False when nothing may go now."""
        raise NotImplementedError

    def _transmit(self, parts: List[Any], flags: int) -> int:
        """Send ``parts`` (``out``, and ``out_fd`` with its first byte) with ``flags``
        (MSG_DONTWAIT, or 0 from the writer thread: blocking); the bytes sent."""
        fd = self.out_fd
        if fd >= 0:
            sent: int = self.stream.sendmsg(parts, [(socket.SOL_SOCKET, socket.SCM_RIGHTS,
                                                     _FD.pack(fd))], flags)
            if sent:  # it went with the first byte
                self.out_fd = -1
                os.close(fd)
            return sent
        if len(parts) == 1:
            sent = self.stream.send(parts[0], flags)
            return sent
        sent = self.stream.sendmsg(parts, (), flags)
        return sent

    def _more(self) -> bool:
        """With the lock, when nothing may go: whether something may now after all (without
        waiting). Shared memory reads the slots given back here."""
        return False

    def _watch(self) -> None:
        """Read what the subscriber sends until the stream ends (or the connection does)."""
        try:
            while not self.done:
                if not self.stream.recv(4096):  # a subscriber never sends after its header
                    return
        except OSError:
            pass

    def _release(self) -> None:
        """With the lock, once: free what the connection holds (its stream first)."""
        sockets.close(self.stream)
        fd, self.out_fd = self.out_fd, -1
        if fd >= 0:
            os.close(fd)

    # -- sending --------------------------------------------------------------------------------

    # ``send`` is each transport's own: the fast path of its wire (one non-blocking send from
    # the publishing thread when the stream is idle) is written out there, not called, since
    # per-message Python on it is counted in tens of nanoseconds (docs/architecture.md's
    # "latency path"); what follows is what both share once a frame has to wait.

    def _enqueue(self, item: Any, frame: Frame) -> bool:
        """With the lock: queue ``item`` (for ``frame``), oldest dropped when the queue is
        full; a publisher a whole queue ahead first waits a moment for room (BACKOFF_*):
        a loop publishing big frames faster than the subscriber takes them would only spin
        and take the CPU the writer and the subscriber need. False when the connection ended
        meanwhile."""
        queue = self.queue
        items = queue.items
        if not queue.limit or len(items) < queue.limit:  # room: the usual case, no call
            items.append(item)
            return True
        if frame.__class__ is not bytes or len(frame) >= sendqueue.BACKOFF_BYTES:
            wait = queue.backoff(frame_size(frame))
            if wait:
                self.room_wanted += 1
                self.space.wait(wait)
                self.room_wanted -= 1
                if self.done:
                    return False
        dropped = queue.put(item)
        if self.on_drop is not None:
            for old in dropped:
                self.on_drop(old)
        return True

    def _pump(self) -> None:
        """With the lock: send what may go now without blocking; what the socket does not
        take waits for the writer thread (or a synchronous publisher's drain)."""
        if self.busy or self.done:
            return
        while True:
            if not self.out and not self._refill():
                return
            try:
                sent = self._transmit(self.out, MSG_DONTWAIT)
            except BlockingIOError:
                sent = 0
            except OSError as exc:
                self._fail(exc)
                return
            if not self._advance(sent):
                self.cond.notify_all()  # the writer (or a drain) sends the rest
                return

    def _refill(self) -> bool:
        """With the lock, ``out`` empty: move what may go next into ``out`` (and tell a
        publisher waiting for room); False when nothing may go now."""
        while not self._next_out():
            if not self._more():
                return False
        if self.room_wanted:
            self.space.notify()
        return True

    def _advance(self, sent: int) -> bool:
        """``sent`` bytes of ``out`` went: True when all of it did."""
        self.bytes_sent += sent
        rest = []
        for part in self.out:
            n = len(part)
            if sent >= n:
                sent -= n
                continue
            rest.append(memoryview(part)[sent:] if sent else part)
            sent = 0
        self.out = rest
        if rest:
            return False
        self.stat_msgs += self.out_count
        self.out_count = 0
        return True

    def _drain(self) -> bool:
        """With the lock, for a synchronous publisher: hand over everything queued before
        returning, waiting for a slow subscriber as long as it keeps taking bytes, but give up
        on one that takes nothing for SYNC_SEND_TIMEOUT seconds. False when the connection
        ended."""
        limit = sendqueue.SYNC_SEND_TIMEOUT
        deadline = time.monotonic() + limit
        progress = self.bytes_sent
        while not self.done and (self.out or self.queue.items or self.control):
            now = time.monotonic()
            if self.bytes_sent != progress:  # it is reading: keep waiting
                progress, deadline = self.bytes_sent, now + limit
            remaining = deadline - now
            if remaining <= 0:
                self._fail(TimeoutError(f"subscriber took nothing for {limit:.0f} s"))
                return False
            if self.out:  # the socket is full (a synchronous sender has no writer)
                wait_writable(self.stream, min(remaining, 1.0))
                self._pump()
                continue
            self._pump()
            if not self.done and not self.out and self.bytes_sent == progress:
                self.cond.wait(min(remaining, 1.0))  # a window: the watcher notifies
        return not self.done

    def _writer(self) -> None:
        """Sends, blocking, what the socket did not take at once, then pumps the rest."""
        cond = self.cond
        while True:
            with cond:
                while not self.out and not self.done:
                    if self.queue.items:  # queued while nothing was out: move it now, or
                        self._pump()  # it waits for good (the writer waits for out only)
                        if self.out or self.done:
                            break
                    cond.wait()
                if self.done:
                    return
                self.busy = True
                parts = list(self.out)
            try:
                sent = self._transmit(parts, 0)
            except OSError as exc:
                with cond:
                    self.busy = False
                    self._fail(exc)
                return
            with cond:
                self.busy = False
                if self._advance(sent) and not self.done:
                    # the next goes the same way, blocking: a non-blocking try right after
                    # the socket filled up would mostly fail (EAGAIN) and cost a raise
                    self._refill()
                cond.notify_all()

    # -- the end --------------------------------------------------------------------------------

    def _watcher(self) -> None:
        error: BaseException | None = None
        try:
            self._watch()
        except Exception as exc:  # noqa: BLE001 - a protocol error of the subscriber's
            error = exc
        if not self.done and not self.closing:
            with self.cond:
                self._fail(error)
        if self.ended:
            try:
                self.on_close(self)
            except Exception:  # noqa: BLE001 - the publication's bug must not go unseen
                _logger.exception("on_close of a connection on [%s] failed", self.topic)

    def _fail(self, exc: BaseException | None) -> None:
        """With the lock: the connection is dead; forget what waits. The stream's end wakes
        the watcher, which tells the publication."""
        if self.done:
            return
        self.ended = not self.closing
        self._end()
        if exc is not None and not isinstance(exc, self.QUIET):
            _logger.info("%s connection to [%s] on [%s] closed: %s", self.protocol,
                         self.callerid, self.topic, exc)

    def _end(self) -> None:
        self.done = True
        self.queue.clear()
        self.out = []
        self.cond.notify_all()
        self.space.notify_all()
        self._release()

    def close(self) -> None:
        if self.done:
            return
        self.closing = True
        # First wake a send in progress (a queue_size=None publish to a slow reader holds the
        # lock for as long as the reader keeps taking bytes): it fails with EPIPE at once.
        try:
            self.stream.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        with self.cond:
            if not self.done:
                self._end()
