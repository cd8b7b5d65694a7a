"""MINROSSHM's publisher end: the queued sender of ``minros.transport.sender`` with shared
memory's wire. A large frame waits in the queue as a frame (shared with every connection, as
over TCPROS) until a slot of the connection's segment is free, is copied into it once, and is
announced with a 28-byte SLOT record while fewer than WINDOW slots are in the subscriber's
hands; small messages go inline on the Unix socket. The watcher reads the slots the
subscriber gives back (DONE), as does a publishing thread that finds the window full.
"""

from __future__ import annotations

import logging
from typing import Any, Callable, List

from minros.transport.base import Frame, Transport
from minros.transport.sender import QueuedSender, frame_size
from minros.transport.shm.segment import Loan, Memory, once, why
from minros.transport.streams import MSG_DONTWAIT, wait_readable
from minros.wire import shm, sockets

__all__ = ["ShmSender"]

#: inline messages sent in one system call at most (the writer catching up)
_BATCH = 256

_rosout = logging.getLogger("rosout")


class ShmSender(QueuedSender):
    """The publisher's end of one subscriber's MINROSSHM connection (``on_close`` as the
    core's; ``on_fallback(topic, reason)`` when shared memory failed for this topic: the
    handler then answers TCPROS to later offers)."""

    protocol = shm.PROTOCOL
    QUIET = (BrokenPipeError, ConnectionResetError, shm.ShmError)

    def __init__(self, stream: Any, topic: str, queue_size: int | None,
                 on_close: Callable[[Transport], Any],
                 on_fallback: Callable[[str, str], Any] | None = None) -> None:
        super().__init__(stream, topic, queue_size, on_close)
        self.memory = Memory(topic, self.control)
        self.slots = self.memory.slots
        self.on_fallback = on_fallback
        self.peer_pid = sockets.peer_pid(stream)
        self.done_reader = shm.DoneReader()  # read by the watcher, or by a publisher (_more)
        self.on_drop = self._dropped

    def info(self) -> str:
        seg = self.memory.segment
        where = f"{seg.slots} slots of {seg.slot_size} bytes" if seg else "no segment yet"
        return (f"MINROSSHM connection (shared memory, {where}) on Unix socket {self.fileno} "
                f"to [pid {self.peer_pid}]")

    # -- publishing ------------------------------------------------------------------------

    def send(self, frame: Frame) -> None:
        """A small frame at once when the socket is idle, else queued; what the window allows
        goes (a synchronous publisher waits until it is handed over)."""
        if self.done or self.failed:
            return
        small = frame.__class__ is bytes
        size = len(frame) if small else frame_size(frame)
        with self.lock:
            if self.done or self.failed:
                return
            if size >= shm.INLINE_LIMIT:
                if not self._fits(size):
                    return  # shared memory failed: the FALL record is on its way
                item: Any = ("frame", frame, size)
            elif small and not self.out and not self.busy and not self.queue.items \
                    and not self.control:  # the socket is idle: one send, as over TCPROS
                data = shm.INLINE + frame  # type: ignore[operator]
                try:
                    sent = self.stream.send(data, MSG_DONTWAIT)
                except BlockingIOError:
                    sent = 0
                except OSError as exc:
                    self._fail(exc)
                    return
                self.bytes_sent += sent
                if sent == len(data):
                    self.stat_msgs += 1
                    return
                self.out, self.out_count = [memoryview(data)[sent:]], 1
                if self.sync:
                    self._drain()
                else:
                    self.cond.notify()  # the writer thread sends the rest
                return
            else:
                item = ("inline", frame)
            if self._enqueue(item, frame):
                self._pump()
                if self.sync:
                    self._drain()

    def _next_out(self) -> bool:
        control = self.control
        if control:
            record, fd = control.pop(0)
            self.out, self.out_fd, self.out_count = [record], fd, 0
            return True
        items = self.queue.items
        if self.failed or not items:
            return False
        if items[0][0] == "inline":  # the inline ones queued after it too: one system call
            out: List[Any] = []
            count = 0
            while items and items[0][0] == "inline" and count < _BATCH:
                frame = items.popleft()[1]
                out.append(shm.INLINE)
                if frame.__class__ is bytes:
                    out.append(frame)
                else:
                    out.extend(frame)
                count += 1
            self.out, self.out_count = out, count
            return True
        # a frame is written into a free slot as soon as there is one, ahead of its announcing
        if items[0][0] == "frame" and not self._write_ahead():
            return False
        if not self.slots.room():
            return False
        _, index, length, offset = items.popleft()
        self.out, self.out_count = [self.slots.announce(index, offset, length)], 1
        return True

    def _write_ahead(self) -> bool:
        """With the lock: the frame at the queue's head copied into a free slot (the one copy
        it costs); False when none is free."""
        index = self._slot()
        if index is None:
            return False
        _, frame, size = self.queue.items[0]
        self.memory.segment.write(index, frame)  # type: ignore[union-attr]
        self.slots.queued(index)
        self.queue.items[0] = ("slot", index, size, 0)
        return True

    def _slot(self, take_back: bool = False) -> int | None:
        """With the lock: a free slot, allocated (None: none, or shared memory failed);
        ``take_back``: when none is free, the frame written ahead gives way."""
        if take_back and not self.slots.counts()["free"]:
            self._drop_written(1)
        try:
            return self.memory.slot()
        except OSError as exc:
            self._unavailable(exc)
            return None

    def _drop_written(self, limit: int = -1) -> None:
        """With the lock: frames written and not announced give way (``limit``, oldest first)."""
        written = [i for i in self.queue.items if i[0] == "slot"]
        for item in written[:limit] if limit >= 0 else written:
            self.queue.items.remove(item)
            self.queue.dropped += 1
            self.slots.abandon(item[1])

    def _dropped(self, item: Any) -> None:  # with the lock: the full queue dropped ``item``
        if item[0] == "slot":
            self.slots.abandon(item[1])


    def _fits(self, size: int) -> bool:
        """With the lock: slots that hold ``size`` bytes (a new segment: the frames written
        into the old one are dropped, those waiting stay); False when shared memory failed."""
        try:
            if self.memory.fit(size):
                self._drop_written()
        except OSError as exc:
            self._unavailable(exc)
            return False
        return True

    def _unavailable(self, exc: OSError) -> None:  # with the lock: the kernel said no
        self._fall_back(f"shared memory for [{self.topic}] unavailable: {why(exc)}")

    def _fall_back(self, reason: str) -> None:
        """With the lock: shared memory failed: FALL tells the subscriber to use TCPROS (one
        log line per distinct reason)."""
        if self.failed:
            return
        self.failed = reason
        if once(reason):
            _rosout.warning("%s; its subscribers use TCPROS", reason)
        self.control.append((shm.fallback(reason), -1))
        self.queue.clear()
        self._pump()
        if self.on_fallback is not None:
            self.on_fallback(self.topic, reason)

    # -- loans (Publisher.loan) --------------------------------------------------------------

    def lend(self, nbytes: int) -> Loan | None:
        """A slot for a message's large array of ``nbytes`` the publisher fills in place (None:
        the connection ended, shared memory failed, a synchronous publisher, the kernel)."""
        with self.lock:
            if self.done or self.failed or self.sync or \
                    not self._fits(shm.LOAN_OFFSET + nbytes + shm.LOAN_TAIL):
                return None
            index = self._slot(take_back=True)
            seg = self.memory.segment
            return seg.lend(index, nbytes) if index is not None and seg is not None else None

    def give_back(self, loan: Any) -> None:
        """A loan not published after all: its slot is free again."""
        with self.lock:
            if loan.segment is self.memory.segment:
                self.slots.abandon(loan.index)

    def send_loaned(self, loan: Any, head: bytes, tail: bytes) -> bool:
        """Publish the message whose array is ``loan``'s memory, its fields written around it
        (no copy); False for a stale loan (a new segment since, the connection ended)."""
        with self.lock:
            seg = self.memory.segment
            if self.done or self.failed or loan.segment is not seg or seg is None:
                return False
            where = seg.write_around(loan, head, tail)
            if where is None:
                self.slots.abandon(loan.index)
                return False
            self.slots.queued(loan.index)
            if self._enqueue(("slot", loan.index, *where), b""):
                self._pump()
        return True

    # -- the subscriber's DONE records -------------------------------------------------------

    def _more(self) -> bool:
        """With the lock, the window full: the DONE records on the socket, without waiting for
        the watcher (a publisher copying frames holds the GIL); True when a slot came back."""
        if not self.queue.items or self.slots.room() or self.failed:
            return False
        try:
            return self._read_done() > 0
        except shm.ShmError as exc:
            self._fail(exc)
        except OSError:  # nothing there (BlockingIOError), or an error the watcher sees
            pass
        return False

    def _read_done(self) -> int:
        """With the lock: the DONE records there are, their slots freed; how many (-1: the
        end of the stream)."""
        n = self.stream.recv_into(self.done_reader.space(), 0, MSG_DONTWAIT)
        if not n:
            return -1
        try:
            records = self.done_reader.received(n)
            for record in records:
                self.slots.done(record.generation, record.slot)
        except shm.ShmError as exc:
            if once(f"{self.topic}: {exc}"):
                _rosout.warning("subscriber [%s] of [%s] broke the shared-memory protocol: "
                                "%s; connection closed", self.callerid, self.topic, exc)
            raise
        return len(records)

    def _watch(self) -> None:
        """Reads the subscriber's DONE records until its end of the stream (waits of 1 s: a
        descriptor closed meanwhile and reused is never waited on long)."""
        while not self.done:
            if wait_readable(self.stream, 1.0):
                with self.cond:
                    try:
                        if self._read_done() < 0:
                            return
                    except BlockingIOError:  # a publishing thread took them
                        continue
                    except OSError:  # the stream closed under us
                        return
                    self._pump()
                    self.cond.notify_all()

    def _release(self) -> None:
        super()._release()
        self.memory.close()
