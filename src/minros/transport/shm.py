"""MINROSSHM: topics between minros nodes of one host through shared memory (the protocol,
without I/O, is ``minros.wire.shm``; its docstring is the specification).

The publisher's end (:class:`ShmSender`) owns a memfd segment of slots per connection, made
when the first large message comes (``memfd_create``: anonymous memory that no file names, so
nothing is left in ``/dev/shm`` whoever is killed; sealed against shrinking, and allocated with
``posix_fallocate`` so that a full machine is an error here, not a SIGBUS later). Publishing
copies the serialized frame into a free slot once and sends a 28-byte SLOT record over the
connection's Unix socket; small messages go inline on the same socket. What waits is queued
per connection as over TCPROS (oldest dropped), and a publish never blocks on a slow
subscriber unless the publisher is synchronous (queue_size=None).

The subscriber's end (:class:`ShmReceiver`) maps each segment read-only and reads every
message from its slot in place: ``uint8[]`` fields (``Image.data``, ``PointCloud2.data``)
are memoryviews of the slot, valid until the callbacks return, when the slot goes back to the
publisher (DONE). A message the callbacks kept (a list, message_filters, a latch) is made
its own then: its views are copied out (:func:`own`).

Anything that goes wrong with shared memory (the kernel refusing a memfd, a segment that
cannot be allocated or mapped, a peer sending garbage) ends the connection with
:class:`~minros.transport.base.FallBack`: the subscriber asks again, offering only TCPROS.
"""

from __future__ import annotations

import fcntl
import logging
import mmap
import os
import secrets
import select
import socket
import struct
import sys
import threading
import time
from typing import Any, Callable, Dict, List, Optional, Set, Tuple

from minros.msgs import reader_for
from minros.transport.base import (
    FallBack,
    Frame,
    ProtocolHandler,
    PublicationSide,
    Transport,
    next_connection_id,
)
from minros.transport.streams import MSG_DONTWAIT
from minros.transport.tcpros_base import CONNECT_TIMEOUT, negotiate
from minros.wire import shm, sockets, tcpros, trace
from minros.wire.handshake import Handshake, Rejected, Role, refusal, route

__all__ = ["ENV", "Loan", "ShmHandler", "ShmReceiver", "ShmSegment", "ShmSender", "boot_id",
           "own", "supported"]

_logger = logging.getLogger("minros.transport.shm")
_rosout = logging.getLogger("rosout")

#: set to 0 to keep a process off shared memory (its subscribers offer only TCPROS, its
#: publishers answer TCPROS)
ENV = "MINROS_SHM"
#: a synchronous (queue_size=None) publisher waits at most this long for a slow subscriber
SYNC_SEND_TIMEOUT = 60.0
#: seconds a connecting subscriber has to send its connection header
HEADER_TIMEOUT = 10.0
#: connections the publisher's socket takes at once before their headers are read
MAX_HANDSHAKES = 64
#: file descriptors one receive takes at most (a segment brings one)
_MAX_FDS = 4
_ANC_SIZE = socket.CMSG_SPACE(_MAX_FDS * 4) if hasattr(socket, "CMSG_SPACE") else 0
_U32 = struct.Struct("<I")
#: inline messages sent in one system call at most (the writer catching up)
_BATCH = 256

_boot_id: Optional[str] = None


def boot_id() -> str:
    """This kernel's boot id ("" when it cannot be read): equal only on one host."""
    global _boot_id
    if _boot_id is None:
        try:
            with open(shm.BOOT_ID_PATH) as f:
                _boot_id = f.read().strip()
        except OSError:
            _boot_id = ""
    return _boot_id


def supported() -> bool:
    """Whether this process speaks MINROSSHM: Linux's memfd, abstract Unix sockets and
    descriptor passing, a boot id, and ``MINROS_SHM`` not 0."""
    if os.environ.get(ENV, "").strip() in ("0", "false", "no", "off"):
        return False
    return (sys.platform.startswith("linux") and hasattr(os, "memfd_create")
            and hasattr(socket, "AF_UNIX") and hasattr(socket, "SCM_RIGHTS")
            and hasattr(fcntl, "F_ADD_SEALS") and bool(boot_id()))


_said: Set[str] = set()
_said_lock = threading.Lock()


def _once(text: str) -> bool:
    """True the first time this process says ``text`` (one line per distinct failure)."""
    with _said_lock:
        if text in _said:
            return False
        _said.add(text)
        return True


def _why(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror + (f" ({exc.__class__.__name__})" if exc.errno is None else "")
    return str(exc) or exc.__class__.__name__


# --------------------------------------------------------------------------- the segment


class ShmSegment:
    """The publisher's memfd of ``slots`` slots of ``slot_size`` bytes, mapped read-write.

    Raises OSError when the kernel refuses it (no memfd, the size over a limit, no memory to
    allocate its header page); :meth:`prepare` allocates a slot before its first use."""

    def __init__(self, topic: str, generation: int, slots: int, slot_size: int) -> None:
        self.generation = generation
        self.slots = slots
        self.slot_size = slot_size
        self.size = shm.HEADER_SIZE + slots * slot_size
        self.fd = os.memfd_create(f"minros-shm:{topic}"[:240],
                                  os.MFD_CLOEXEC | os.MFD_ALLOW_SEALING)
        try:
            os.ftruncate(self.fd, self.size)
            # a subscriber cannot shrink it under our writes (SIGBUS), nor we under its reads
            fcntl.fcntl(self.fd, fcntl.F_ADD_SEALS,
                        fcntl.F_SEAL_SHRINK | fcntl.F_SEAL_GROW | fcntl.F_SEAL_SEAL)
            os.posix_fallocate(self.fd, 0, shm.HEADER_SIZE)
            self.map = mmap.mmap(self.fd, self.size)
        except BaseException:
            os.close(self.fd)
            raise
        self.view = memoryview(self.map)
        header = shm.segment_header(generation, slots, slot_size)
        self.view[:len(header)] = header
        self.allocated = [False] * slots

    def prepare(self, index: int) -> None:
        """Allocate slot ``index``'s memory on its first use (OSError when there is none)."""
        if not self.allocated[index]:
            os.posix_fallocate(self.fd, shm.HEADER_SIZE + index * self.slot_size, self.slot_size)
            self.allocated[index] = True

    def write(self, index: int, frame: Frame) -> int:
        """Copy ``frame`` into slot ``index`` (the one copy a message costs); its length."""
        pos = shm.HEADER_SIZE + index * self.slot_size
        view = self.view
        if isinstance(frame, bytes):
            n = len(frame)
            view[pos:pos + n] = frame
            return n
        start = pos
        for part in frame:
            n = len(part)
            view[pos:pos + n] = part
            pos += n
        return pos - start

    def close(self) -> None:
        """Unmap and close (the subscriber's mapping keeps the memory while it lasts)."""
        fd, self.fd = self.fd, -1
        if fd >= 0:
            os.close(fd)
        try:
            self.view.release()
            self.map.close()
        except BufferError:  # a copy in progress holds a view: the mapping goes with it
            pass


# --------------------------------------------------------------------------- the publisher's end


class ShmSender(Transport):
    """The publisher's end of one subscriber's MINROSSHM connection.

    ``on_close(self)`` runs once, in a thread of its own, when the connection fails or the
    subscriber leaves (not when :meth:`close` is called); ``on_fallback(topic, reason)`` when
    shared memory failed for this topic (the handler then answers TCPROS to later offers)."""

    protocol = shm.PROTOCOL

    def __init__(self, stream: Any, topic: str, queue_size: int | None,
                 on_close: Callable[[Transport], Any],
                 on_fallback: Callable[[str, str], Any] | None = None) -> None:
        self.id = next_connection_id()
        self.stream = stream
        self.topic = topic
        self.header: Dict[str, str] = {}
        self.stat_msgs = 0
        self.bytes_sent = 0
        self.done = False
        self.sync = queue_size is None
        self.slots = shm.SlotQueue(shm.slot_count(queue_size), queue_size)
        self.segment: ShmSegment | None = None
        self.control: List[Tuple[bytes, int]] = []  # SEGM/FALL records first, with their fd
        self.out: List[Any] = []  # the unsent rest of the record being sent
        self.out_fd = -1  # the descriptor to attach to out's first byte
        self.out_item = 0  # the messages in out
        self.failed = ""  # why shared memory failed: nothing more is sent but the FALL
        self.lock = threading.Lock()
        self.cond = threading.Condition(self.lock)
        self.busy = False  # the writer thread sends out without the lock
        self.on_close = on_close
        self.on_fallback = on_fallback
        self.peer_pid = _peer_pid(stream)
        self.fileno = stream.fileno()
        # the subscriber's DONE records: read by the watcher thread, and by a publishing
        # thread that finds the window full (it holds the GIL while it copies frames, so the
        # watcher would wait up to sys.getswitchinterval() to free each slot)
        self.done_reader = shm.DoneReader()
        self.reading = threading.Lock()

    @property
    def stat_bytes(self) -> int:
        return self.bytes_sent

    @property
    def callerid(self) -> str:
        return self.header.get("callerid", "")

    @property
    def endpoint_id(self) -> str:
        return self.callerid

    def info(self) -> str:
        seg = self.segment
        where = (f"{seg.slots} slots of {seg.slot_size} bytes" if seg is not None
                 else "no segment yet")
        return (f"MINROSSHM connection (shared memory, {where}) on Unix socket {self.fileno} "
                f"to [pid {self.peer_pid}]")

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        """Answer the subscriber's header; then the connection's threads start: a writer for
        what the socket did not take, and one reading the subscriber's DONE records."""
        self.header = negotiate(self.stream, handshake, opening)
        threading.Thread(target=self._writer, daemon=True,
                         name=f"minros-pub:{self.topic}").start()
        threading.Thread(target=self._watch, daemon=True,
                         name=f"minros-pub-watch:{self.topic}").start()

    # -- publishing ------------------------------------------------------------------------

    def send(self, frame: Frame) -> None:
        """Queue ``frame`` (copied into a slot when large) and send what the window allows;
        a synchronous publisher waits until it is handed over."""
        if self.done or self.failed:
            return
        size = len(frame) if isinstance(frame, bytes) else sum(len(p) for p in frame)
        if size < shm.INLINE_LIMIT:
            with self.lock:
                if (isinstance(frame, bytes) and not self.busy and not self.out
                        and not self.control and not self.slots.items and not self.sync
                        and not self.done):
                    # the socket is idle: one non-blocking send, as TCPROS does
                    data = shm.INLINE + frame
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
                    self.out, self.out_item = [memoryview(data)[sent:]], 1
                    self.cond.notify_all()  # the writer thread sends the rest
                    return
                if self.sync and not self._wait_drained():
                    return
                self.slots.put(("inline", frame))
                self._pump()
                if self.sync:
                    self._wait_drained()
            return
        with self.lock:
            if self.sync and not self._wait_drained():
                return
            index = self._slot_for(size)
        if index is None:
            return
        seg = self.segment
        assert seg is not None
        try:
            seg.write(index, frame)  # outside the lock: the slot is ours until queued
        except ValueError:  # the segment was closed meanwhile
            return
        with self.lock:
            if self.done or self.failed or seg is not self.segment:
                return
            self.slots.put(("slot", index, size, 0))
            self._pump()
            if self.sync:
                self._wait_drained()

    # -- loans (Publisher.loan) --------------------------------------------------------------

    def lend(self, nbytes: int) -> Loan | None:
        """A slot for a message whose large array (``nbytes``) the publisher fills in place:
        the array's memory at LOAN_OFFSET in it. None when there is none to lend (the
        connection ended, shared memory failed, a synchronous publisher, the kernel)."""
        with self.lock:
            if self.done or self.failed or self.sync:
                return None
            index = self._slot_for(shm.LOAN_OFFSET + nbytes + shm.LOAN_TAIL)
            seg = self.segment
            if index is None or seg is None:
                return None
            start = shm.HEADER_SIZE + index * seg.slot_size + shm.LOAN_OFFSET
            return Loan(seg, index, seg.view[start:start + nbytes])

    def give_back(self, loan: Loan) -> None:
        """A loan not published after all: its slot is free again."""
        with self.lock:
            if loan.segment is self.segment:
                self.slots.abandon(loan.index)

    def send_loaned(self, loan: Loan, head: bytes, tail: bytes) -> bool:
        """Publish the message whose array is ``loan``'s memory: ``head`` (the frame's length
        prefix and the fields before the array) and ``tail`` (the fields after it) are written
        around it, nothing is copied. False when the loan is stale (a new segment since, the
        connection ended): the caller then sends the message as any other."""
        with self.lock:
            seg = self.segment
            if self.done or self.failed or loan.segment is not seg or seg is None:
                return False
            n = len(loan.view)
            if len(head) > shm.LOAN_OFFSET or shm.LOAN_OFFSET + n + len(tail) > seg.slot_size:
                self.slots.abandon(loan.index)
                return False
            base = shm.HEADER_SIZE + loan.index * seg.slot_size
            start = base + shm.LOAN_OFFSET - len(head)
            seg.view[start:base + shm.LOAN_OFFSET] = head
            end = base + shm.LOAN_OFFSET + n
            seg.view[end:end + len(tail)] = tail
            self.slots.put(("slot", loan.index, len(head) + n + len(tail), start - base))
            self._pump()
        return True

    def _slot_for(self, size: int) -> int | None:
        """With the lock: a slot of a segment large enough for ``size`` bytes, or None (the
        frame is dropped, or shared memory failed and the FALL record is on its way)."""
        seg = self.segment
        try:
            if seg is None or size > seg.slot_size:
                seg = self._new_segment(size)
            index = self.slots.acquire()
            if index is None:  # the subscriber holds every slot (cannot happen: WINDOW < slots)
                return None
            try:
                seg.prepare(index)
            except BaseException:
                self.slots.abandon(index)
                raise
            return index
        except OSError as exc:
            self._fall_back(f"shared memory for [{self.topic}] unavailable: {_why(exc)}")
            return None

    def _new_segment(self, size: int) -> ShmSegment:
        old = self.segment
        generation = old.generation + 1 if old is not None else 1
        slot_size = shm.grown_slot_size(size, old.slot_size if old is not None else 0)
        seg = ShmSegment(self.topic, generation, len(self.slots.state), slot_size)
        self.slots.resize(len(self.slots.state), generation)
        # an announcement still unsent names an older segment: no longer needed
        for _record, fd in self.control:
            if fd >= 0:
                os.close(fd)
        self.control = [(shm.segment(generation, seg.slots, seg.slot_size), os.dup(seg.fd))]
        self.segment = seg
        if old is not None:
            old.close()  # the subscriber's mapping keeps what it still reads
        return seg

    def _fall_back(self, reason: str) -> None:
        """With the lock: shared memory failed; tell the subscriber (FALL), which connects
        again over TCPROS. One log line per distinct reason."""
        if self.failed:
            return
        self.failed = reason
        if _once(reason):
            _rosout.warning("%s; its subscribers use TCPROS", reason)
        self.control.append((shm.fallback(reason), -1))
        self.slots.items.clear()
        self._pump()
        if self.on_fallback is not None:
            self.on_fallback(self.topic, reason)

    def _wait_drained(self) -> bool:
        """With the lock, for a synchronous publisher: wait until everything queued is in the
        subscriber's hands (False when the connection ended or stalled for
        SYNC_SEND_TIMEOUT)."""
        deadline = time.monotonic() + SYNC_SEND_TIMEOUT
        while self.slots.items or self.out or self.control or self.busy:
            if self.done:
                return False
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                self._fail(TimeoutError(f"subscriber took nothing for {SYNC_SEND_TIMEOUT:.0f} s"))
                return False
            self.cond.wait(remaining)
        return not self.done

    def _pump(self) -> None:
        """With the lock: send what may be sent now without blocking; what the socket does not
        take waits for the writer thread."""
        if self.busy or self.done:
            return
        stream = self.stream
        while True:
            if not self.out:
                if not self._next_out():
                    slots = self.slots
                    if (slots.items and slots.in_flight >= slots.window and not self.failed
                            and self._take_done()):
                        continue  # slots came back: the window has room again
                    return
            try:
                if self.out_fd >= 0:
                    sent = stream.sendmsg(self.out, [(socket.SOL_SOCKET, socket.SCM_RIGHTS,
                                                      _U32.pack(self.out_fd))], MSG_DONTWAIT)
                else:
                    sent = stream.sendmsg(self.out, (), MSG_DONTWAIT)
            except BlockingIOError:
                sent = 0
            except OSError as exc:
                self._fail(exc)
                return
            if sent and self.out_fd >= 0:
                os.close(self.out_fd)  # it went with the first byte
                self.out_fd = -1
            if not self._advance(sent):
                self.cond.notify_all()  # the writer thread waits for the socket
                return

    def _next_out(self) -> bool:
        """With the lock: the next record to send into ``out``; False when nothing may go."""
        if self.control:
            record, fd = self.control.pop(0)
            self.out, self.out_fd, self.out_item = [record], fd, 0
            return True
        slots = self.slots
        if self.failed or not slots.ready():
            return False
        item, notice = slots.pop()
        if notice is not None:
            self.out, self.out_item = [notice], 1
            return True
        # inline (the frame carries its length prefix), with the inline ones queued after it:
        # one system call for many small messages
        out: List[Any] = []
        count = 0
        while True:
            frame: Any = item[1]
            out.append(shm.INLINE)
            if frame.__class__ is bytes:
                out.append(frame)
            else:
                out.extend(frame)
            count += 1
            items = slots.items
            if count >= _BATCH or not items or items[0][0] != "inline":
                break
            item, _ = slots.pop()
        self.out, self.out_item = out, count
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
        self.stat_msgs += self.out_item
        self.out_item = 0
        return True

    def _writer(self) -> None:
        """Sends, blocking, what the socket did not take at once."""
        cond = self.cond
        stream = self.stream
        while True:
            with cond:
                while not self.done and not self.out:
                    cond.wait()
                if self.done:
                    return
                self.busy = True
                parts, fd = list(self.out), self.out_fd
            try:
                if fd >= 0:
                    sent = stream.sendmsg(parts, [(socket.SOL_SOCKET, socket.SCM_RIGHTS,
                                                   _U32.pack(fd))])
                else:
                    sent = stream.sendmsg(parts)
            except OSError as exc:
                with cond:
                    self.busy = False
                    self._fail(exc)
                return
            with cond:
                self.busy = False
                if sent and self.out_fd >= 0:
                    os.close(self.out_fd)
                    self.out_fd = -1
                if self._advance(sent):
                    self._pump()
                cond.notify_all()

    def _take_done(self) -> bool:
        """With the lock: the DONE records already on the socket, read without blocking (and
        without waiting for the watcher thread); True when a slot came back."""
        if not self.reading.acquire(blocking=False):
            return False  # the watcher is reading them
        try:
            try:
                n = self.stream.recv_into(self.done_reader.space(), 0, MSG_DONTWAIT)
            except OSError:  # nothing there (BlockingIOError), or an error the watcher sees
                return False
            if not n:
                return False  # the end of the stream: the watcher sees it too
            records = self.done_reader.received(n)
            for record in records:
                self.slots.done(record.generation, record.slot)
        except shm.ShmError as exc:
            self._broken(exc)
            self._fail(exc)
            return False
        finally:
            self.reading.release()
        return bool(records)

    def _broken(self, exc: shm.ShmError) -> None:
        if _once(f"{self.topic}: {exc}"):
            _rosout.warning("subscriber [%s] of [%s] broke the shared-memory protocol: %s; "
                            "connection closed", self.callerid, self.topic, exc)

    def _watch(self) -> None:
        """Reads the subscriber's DONE records; its end of the stream ends the connection."""
        reader = self.done_reader
        poller = select.poll()
        poller.register(self.fileno, select.POLLIN)
        error: BaseException | None = None
        try:
            while not self.done:
                # readable, then read under the lock a publishing thread shares (the timeout:
                # a descriptor closed meanwhile and reused is never waited on for long)
                if not poller.poll(1000):
                    continue
                with self.reading:
                    try:
                        n = self.stream.recv_into(reader.space(), 0, MSG_DONTWAIT)
                    except BlockingIOError:  # a publishing thread took them
                        continue
                    if not n:
                        break
                    records = reader.received(n)
                with self.cond:
                    for record in records:
                        self.slots.done(record.generation, record.slot)
                    self._pump()
                    self.cond.notify_all()
        except shm.ShmError as exc:
            error = exc
            self._broken(exc)
        except OSError as exc:
            error = exc
        if not self.done:
            with self.cond:
                self._fail(error)

    def _fail(self, exc: BaseException | None) -> None:
        """With the lock: the connection is dead, forget it."""
        if self.done:
            return
        self.done = True
        self.cond.notify_all()
        if exc is not None and not isinstance(exc, (BrokenPipeError, ConnectionResetError,
                                                    shm.ShmError)):
            _logger.info("shared-memory connection to [%s] on [%s] closed: %s",
                         self.callerid, self.topic, exc)
        self._release()
        threading.Thread(target=self.on_close, args=(self,), daemon=True,
                         name=f"minros-pub-close:{self.topic}").start()

    def _release(self) -> None:
        sockets.close(self.stream)
        for _record, fd in self.control:
            if fd >= 0:
                os.close(fd)
        self.control = []
        if self.out_fd >= 0:
            os.close(self.out_fd)
            self.out_fd = -1
        seg, self.segment = self.segment, None
        if seg is not None:
            seg.close()

    def close(self) -> None:
        if self.done:
            return
        try:
            self.stream.shutdown(socket.SHUT_RDWR)  # wakes the writer and the watcher
        except OSError:
            pass
        with self.cond:
            if self.done:
                return
            self.done = True
            self.cond.notify_all()
            self._release()


class Loan:
    """A slot lent to the publisher: ``view`` is the writable memory of the array it fills."""

    __slots__ = ("segment", "index", "view")

    def __init__(self, segment: ShmSegment, index: int, view: memoryview) -> None:
        self.segment = segment
        self.index = index
        self.view = view


def _peer_pid(stream: Any) -> int:
    try:
        creds = stream.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, struct.calcsize("3i"))
        return int(struct.unpack("3i", creds)[0])
    except (OSError, AttributeError, struct.error):
        return 0


# --------------------------------------------------------------------------- the subscriber's end


class _Mapping:
    """A segment mapped read-only by the subscriber."""

    __slots__ = ("segment", "map", "view")

    def __init__(self, segment: shm.Segment, fd: int) -> None:
        self.segment = segment
        try:
            size = os.fstat(fd).st_size
            if size != segment.size:
                raise shm.ShmError(f"a segment of {size} bytes was announced as {segment.size}")
            seals = fcntl.fcntl(fd, fcntl.F_GET_SEALS)
            if not seals & fcntl.F_SEAL_SHRINK:
                raise shm.ShmError("the segment is not sealed against shrinking")
            self.map = mmap.mmap(fd, size, flags=mmap.MAP_SHARED, prot=mmap.PROT_READ)
        except OSError as exc:
            raise shm.ShmError(f"cannot map the segment: {_why(exc)}") from None
        finally:
            os.close(fd)
        self.view = memoryview(self.map)
        try:
            shm.check_segment_header(self.view, segment)
        except shm.ShmError:
            self.close()
            raise

    def close(self) -> None:
        try:
            self.view.release()
            self.map.close()
        except BufferError:  # views a callback kept: unmapped when they go
            pass


class ShmReceiver(Transport):
    """The subscriber's end of its MINROSSHM connection to one publisher."""

    protocol = shm.PROTOCOL

    def __init__(self, stream: Any, topic: str) -> None:
        self.id = next_connection_id()
        self.stream = stream
        self.topic = topic
        self.header: Dict[str, str] = {}
        self.stat_msgs = 0
        self.done = False
        self.notices = shm.NoticeReader()
        self.bytes_received = 0
        self.maps: Dict[int, _Mapping] = {}
        self.fds: List[int] = []
        self.held: List[bytes] = []  # DONE records of the frames given out last time
        self.latching = False
        self.peer_pid = _peer_pid(stream)
        self.fileno = stream.fileno()
        self.settle: Callable[[Any], None] | None = self._settle

    @property
    def stat_bytes(self) -> int:
        return self.bytes_received

    def info(self) -> str:
        return (f"MINROSSHM connection (shared memory) on Unix socket {self.fileno} to "
                f"[pid {self.peer_pid}]")

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        self.header = negotiate(self.stream, handshake)
        self.stream.settimeout(None)
        self.latching = self.header.get("latching", "0") == "1"

    def message_reader(self, data_class: Any) -> Callable[[Any], Any]:
        """Messages read in place: their byte arrays are views of the slot."""
        if not getattr(data_class, "_zero_copy", True):
            self.settle = None  # no byte or numeric array anywhere: nothing to settle
        read: Callable[[Any], Any] = reader_for(data_class, in_place=True)
        return read

    def _settle(self, msg: Any) -> None:
        """After the callbacks: a message kept beyond them (referenced from anywhere but the
        receive loop, or latched) gets copies of its views before the slot goes back."""
        # references: the receive loop's variable and what the call itself holds
        if self.latching or sys.getrefcount(msg) > 1 + _CALL_REFS:
            own(msg)

    def receive(self) -> List[Any] | None:
        """The messages the publisher announced since the last call, whose slots are given
        back first (the receive loop is done with them)."""
        if self.held:
            try:
                self.stream.sendall(b"".join(self.held))
            except OSError:  # the publisher went away: the receive below sees the end
                pass
            self.held = []
        if len(self.maps) > 1:
            newest = max(self.maps)
            for generation in [g for g in self.maps if g != newest]:
                self.maps.pop(generation).close()
        n, ancdata, flags, _ = self.stream.recvmsg_into([self.notices.space()], _ANC_SIZE)
        self._take_fds(ancdata)
        if flags & getattr(socket, "MSG_CTRUNC", 0):
            raise FallBack("a file descriptor the publisher sent was lost (too many open files?)")
        if not n:
            if self.notices.pending:
                raise tcpros.FrameError("the publisher stopped in the middle of a record")
            return None
        self.bytes_received += n
        try:
            return self._frames(self.notices.received(n))
        except shm.ShmError as exc:
            raise FallBack(f"the publisher broke the shared-memory protocol: {exc}") from None

    def _take_fds(self, ancdata: Any) -> None:
        for level, kind, data in ancdata:
            if level == socket.SOL_SOCKET and kind == socket.SCM_RIGHTS:
                count = len(data) // 4
                self.fds.extend(struct.unpack(f"{count}i", data[:count * 4]))
        if len(self.fds) > _MAX_FDS:
            self._close_fds()
            raise FallBack("the publisher sent more file descriptors than segments")

    def _close_fds(self) -> None:
        fds, self.fds = self.fds, []
        for fd in fds:
            os.close(fd)

    def _frames(self, notices: List[Any]) -> List[Any]:
        if not self.fds and notices and all(n.__class__ is bytes for n in notices):
            return notices  # only small messages: the usual case of a small-message topic
        frames: List[Any] = []
        for notice in notices:
            cls = notice.__class__
            if cls is bytes:
                frames.append(notice)
            elif cls is shm.Slot:
                mapping = self.maps.get(notice.generation)
                if mapping is None:
                    raise shm.ShmError(f"a slot of segment {notice.generation}, which never came")
                seg = mapping.segment
                offset, length = notice.offset, notice.length
                if notice.slot >= seg.slots or length < 4 or offset + length > seg.slot_size:
                    raise shm.ShmError(f"slot {notice.slot} ({length} bytes at {offset}) is "
                                       f"outside the segment of {seg.slots} slots of "
                                       f"{seg.slot_size} bytes")
                start = shm.HEADER_SIZE + notice.slot * seg.slot_size + offset
                frame = mapping.view[start:start + length]
                self.held.append(shm.done(notice.generation, notice.slot))
                if _U32.unpack_from(frame)[0] != length - 4:
                    raise shm.ShmError(f"slot {notice.slot} does not hold the message announced")
                frames.append(frame[4:])
            elif cls is shm.Segment:
                if not self.fds:
                    raise shm.ShmError("a segment came without its file descriptor")
                fd = self.fds.pop(0)
                if notice.generation in self.maps:
                    os.close(fd)
                    raise shm.ShmError(f"segment {notice.generation} announced twice")
                self.maps[notice.generation] = _Mapping(notice, fd)
            else:  # Fallback
                raise FallBack(f"the publisher gave up on shared memory: {notice}")
        if self.fds and not self.notices.pending:
            self._close_fds()
            raise shm.ShmError("a file descriptor came without a segment")
        return frames

    def close(self) -> None:
        if self.done:
            return
        self.done = True
        try:
            self.stream.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        sockets.close(self.stream)
        self._close_fds()
        maps, self.maps = self.maps, {}
        for mapping in maps.values():
            mapping.close()


class _RefProbe:
    def refs(self, obj: Any) -> int:
        return sys.getrefcount(obj)


def _call_refs() -> int:
    """The references a call like ``settle(msg)`` (a bound method in a local) adds to its
    argument, as ``getrefcount`` sees them inside: the parameter and getrefcount's argument,
    and before Python 3.11 the caller's stack slot too."""
    obj = object()
    refs = _RefProbe().refs
    return refs(obj) - 1  # less the caller's own variable


#: measured, not assumed: the calling convention changed in 3.11 (and may again)
_CALL_REFS = _call_refs()


def own(msg: Any) -> None:
    """Give ``msg`` (and the messages it holds) copies of every field that is a view of
    received memory: memoryviews become bytes, numpy views arrays of their own."""
    if not getattr(msg.__class__, "_zero_copy", True):
        return  # no byte or numeric arrays anywhere in it
    stack = [msg]
    while stack:
        obj = stack.pop()
        for name in getattr(obj.__class__, "__slots__", ()):
            value: Any = getattr(obj, name, None)
            cls = value.__class__
            if cls is memoryview:
                setattr(obj, name, value.tobytes())
            elif cls is list:
                stack.extend(item for item in value if hasattr(item, "_slot_types"))
            elif hasattr(value, "_slot_types"):
                stack.append(value)
            elif getattr(value, "base", None) is not None and hasattr(value, "__array_interface__"):
                setattr(obj, name, value.copy())


# --------------------------------------------------------------------------- the protocol


class ShmHandler(ProtocolHandler):
    """MINROSSHM for a node: offered first by its subscribers; its publications answer it
    from ``lookup(topic)`` and serve it on an abstract Unix socket of their own."""

    protocol = shm.PROTOCOL

    def __init__(self, lookup: Callable[[str], PublicationSide | None],
                 shutting_down: Callable[[], bool]) -> None:
        self.boot_id = boot_id()
        self.lookup = lookup
        self.shutting_down = shutting_down
        self.declined: Dict[str, str] = {}  # topic -> why shared memory failed for it
        self._server: _Server | None = None
        self._lock = threading.Lock()

    def offer(self) -> List[Any]:
        return shm.offer(self.boot_id)

    def answer(self, topic: str, offer: List[Any]) -> List[Any] | None:
        if shm.check_offer(offer, self.boot_id) is not None or topic in self.declined:
            return None
        try:
            name = self.server().name
        except OSError as exc:
            _logger.debug("no shared-memory socket: %s", exc)
            return None
        return shm.answer(name, self.boot_id)

    def server(self) -> _Server:
        with self._lock:
            if self._server is None:
                self._server = _Server(self)
            return self._server

    def connect(self, answer: List[Any], topic: str, buff_size: int, reuse_big: bool,
                tcp_nodelay: bool) -> Transport:
        name = shm.parse_answer(answer, self.boot_id)
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(CONNECT_TIMEOUT)
        try:
            sock.bind("")  # an abstract name of our own, so traces can tell connections apart
            sock.connect("\0" + name)
        except OSError as exc:
            sock.close()
            raise FallBack(f"cannot reach the publisher's shared-memory socket: {_why(exc)} "
                           "(another network namespace?)") from None
        return ShmReceiver(trace.watch(sock, "connect", shm.PROTOCOL), topic)

    def accept(self, stream: Any, header: Dict[str, str], publication: PublicationSide) -> None:
        refuse = None
        if publication.closed:
            refuse = f"Internal error processing topic [{publication.resolved_name}]"
        handshake = Handshake(Role.PUBLISHER, publication.header_fields(), refuse=refuse)
        sender = ShmSender(stream, publication.resolved_name, publication.queue_size,
                           publication.remove_connection, self._fell_back)
        sender.negotiate(handshake, header)
        publication.add_connection(sender)

    def _fell_back(self, topic: str, reason: str) -> None:
        self.declined[topic] = reason

    def close(self) -> None:
        with self._lock:
            server, self._server = self._server, None
        if server is not None:
            server.close()


class _Server:
    """The publisher's abstract Unix socket (nothing on disk; reachable from this network
    namespace only): a thread accepts, a thread per connection reads its header."""

    def __init__(self, handler: ShmHandler) -> None:
        self.handler = handler
        self.name = f"minros-shm.{os.getpid()}.{secrets.token_hex(8)}"
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            self.sock.bind("\0" + self.name)
            self.sock.listen(128)
        except OSError:
            self.sock.close()
            raise
        self.closed = threading.Event()
        self.handshakes = threading.BoundedSemaphore(MAX_HANDSHAKES)
        threading.Thread(target=self._accept_loop, daemon=True,
                         name="minros-shm-server").start()

    def _accept_loop(self) -> None:
        while not self.closed.is_set():
            try:
                sock, _ = self.sock.accept()
            except OSError:
                if self.closed.is_set():
                    return
                self.closed.wait(0.01)  # e.g. out of file descriptors: back off
                continue
            if not self.handshakes.acquire(blocking=False):
                sockets.close(sock)  # a flood of connections that say nothing
                continue
            try:
                threading.Thread(target=self._handle, args=(sock,), daemon=True,
                                 name="minros-shm-inbound").start()
            except RuntimeError:
                self.handshakes.release()
                sockets.close(sock)

    def _handle(self, raw: socket.socket) -> None:
        handler = self.handler
        sock = trace.watch(raw, "accept", shm.PROTOCOL)
        try:
            try:
                header = sockets.read_header(sock, deadline=time.monotonic() + HEADER_TIMEOUT)
            except (OSError, tcpros.HeaderError) as exc:
                if not handler.shutting_down():
                    _rosout.warning("Inbound shared-memory connection failed: %s", exc)
                sockets.close(sock)
                return
            finally:
                self.handshakes.release()
            sock.settimeout(None)
            error = None
            publication = None
            if handler.shutting_down():
                error = "Node is shutting down"
            elif route(header) != "topic":
                error = "a shared-memory connection carries a topic"
            else:
                publication = handler.lookup(header["topic"])
                if publication is None:
                    error = f"not a publisher of [{header['topic']}]"
            if publication is not None:
                try:
                    handler.accept(sock, header, publication)
                    return
                except Rejected as exc:
                    _rosout.warning("Could not process inbound connection: %s%s", exc, header)
                    sockets.close(sock)
                    return
            try:
                sock.sendall(refusal(error or "refused"))
            except OSError:
                pass
            sockets.close(sock)
        except Exception:  # noqa: BLE001 - one connection's failure must not end the server
            _logger.error("shared-memory connection failed", exc_info=True)
            sockets.close(sock)

    def close(self) -> None:
        self.closed.set()
        sockets.close(self.sock)

