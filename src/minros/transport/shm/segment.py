"""What MINROSSHM asks of the kernel: whether this process may use shared memory, the
publisher's segment (a sealed memfd) and the subscriber's read-only mapping of it.

The publisher's segment is anonymous memory no file names (``memfd_create``: nothing is left in
``/dev/shm`` whoever is killed), sealed against shrinking and growing, and allocated slot by
slot with ``posix_fallocate`` so that a full machine is an error here, not a SIGBUS later.

Only the publisher writes it. It maps the memfd read-write first, then seals it with
``F_SEAL_FUTURE_WRITE`` (Linux 5.1): from then on the kernel refuses any new writable shared
mapping and any ``write(2)``, whichever descriptor asks, while the mapping the publisher made
keeps working. The descriptor a subscriber gets is a read-only reopening
(``/proc/self/fd/N``, O_RDONLY) besides. The seal is what protects: a read-only descriptor
alone is not enough, since the receiver can reopen ``/proc/self/fd/N`` read-write (a memfd's
mode is 0777) and map that; and ``F_SEAL_WRITE`` cannot be used, since it refuses while the
publisher's own writable mapping exists. A kernel without the seal keeps its processes on
TCPROS.
"""

from __future__ import annotations

import fcntl
import mmap
import os
import socket
import sys
import threading
from typing import List, Optional, Set, Tuple

from minros.transport.base import Frame
from minros.wire import shm
from minros.wire import trace as _trace

__all__ = ["ENV", "F_SEAL_FUTURE_WRITE", "TRACE_ENV", "Loan", "Mapping", "Memory", "ShmSegment",
           "boot_id", "supported"]

#: set to 0 to keep a process off shared memory (its subscribers offer only TCPROS, its
#: publishers answer TCPROS)
ENV = "MINROS_SHM"
#: a traced process (MINROS_TRACE) keeps to TCPROS, so the trace shows the wire courses teach,
#: unless this is 1 (``minros trace --shm``)
TRACE_ENV = "MINROS_TRACE_SHM"
#: Linux's seal against writes through any new mapping or descriptor (Python's fcntl has the
#: name from 3.13 on)
F_SEAL_FUTURE_WRITE: int = getattr(fcntl, "F_SEAL_FUTURE_WRITE", 0x0010)

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


def _off(value: str) -> bool:
    return value.strip().lower() in ("0", "false", "no", "off")


def supported() -> bool:
    """Whether this process speaks MINROSSHM: Linux's memfd, abstract Unix sockets and
    descriptor passing, a boot id, ``MINROS_SHM`` not 0, and not traced (MINROS_TRACE)
    unless ``MINROS_TRACE_SHM`` is 1."""
    if _off(os.environ.get(ENV, "")):
        return False
    if os.environ.get(_trace.ENV_FILE) and os.environ.get(TRACE_ENV, "") != "1":
        return False
    return (sys.platform.startswith("linux") and hasattr(os, "memfd_create")
            and hasattr(socket, "AF_UNIX") and hasattr(socket, "SCM_RIGHTS")
            and hasattr(fcntl, "F_ADD_SEALS") and bool(boot_id()))


_said: Set[str] = set()
_said_lock = threading.Lock()


def once(text: str) -> bool:
    """True the first time this process says ``text`` (one line per distinct failure)."""
    with _said_lock:
        if text in _said:
            return False
        _said.add(text)
        return True


def why(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror + (f" ({exc.__class__.__name__})" if exc.errno is None else "")
    return str(exc) or exc.__class__.__name__


class ShmSegment:
    """The publisher's memfd of ``slots`` slots of ``slot_size`` bytes, mapped read-write by the
    publisher only (sealed: see the module's docstring).

    Raises OSError when the kernel refuses it (no memfd, the size over a limit, no memory to
    allocate its header page, no seal); :meth:`prepare` allocates a slot before its first
    use."""

    def __init__(self, topic: str, generation: int, slots: int, slot_size: int) -> None:
        self.generation = generation
        self.slots = slots
        self.slot_size = slot_size
        self.size = shm.HEADER_SIZE + slots * slot_size
        self.fd = os.memfd_create(f"minros-shm:{topic}"[:240],
                                  os.MFD_CLOEXEC | os.MFD_ALLOW_SEALING)
        try:
            os.ftruncate(self.fd, self.size)
            os.posix_fallocate(self.fd, 0, shm.HEADER_SIZE)
            self.map = mmap.mmap(self.fd, self.size)
            try:
                # a subscriber can neither shrink it under our writes (SIGBUS), nor we under
                # its reads, nor anyone but this mapping write it
                fcntl.fcntl(self.fd, fcntl.F_ADD_SEALS,
                            fcntl.F_SEAL_SHRINK | fcntl.F_SEAL_GROW | F_SEAL_FUTURE_WRITE
                            | fcntl.F_SEAL_SEAL)
            except OSError as exc:
                self.map.close()
                raise OSError(exc.errno, "the kernel cannot seal shared memory against the "
                              "subscribers' writes (F_SEAL_FUTURE_WRITE, Linux 5.1)") from None
        except BaseException:
            os.close(self.fd)
            raise
        self.view = memoryview(self.map)
        header = shm.segment_header(generation, slots, slot_size)
        self.view[:len(header)] = header
        self.allocated = [False] * slots

    @classmethod
    def for_frame(cls, topic: str, size: int, old: ShmSegment | None) -> ShmSegment:
        """A segment whose slots hold a frame of ``size`` bytes: the first one, or one larger
        than ``old`` (half as large again at least, so that growing messages make few)."""
        generation = old.generation + 1 if old is not None else 1
        slot_size = shm.grown_slot_size(size, old.slot_size if old is not None else 0)
        return cls(topic, generation, shm.SLOTS, slot_size)

    def announcement(self) -> Tuple[bytes, int]:
        """Its SEGM record and the descriptor a subscriber gets with it: opened read-only
        (the seal keeps it so even reopened; without /proc, a duplicate, as sealed)."""
        record = shm.segment(self.generation, self.slots, self.slot_size)
        try:
            return record, os.open(f"/proc/self/fd/{self.fd}", os.O_RDONLY | os.O_CLOEXEC)
        except OSError:
            return record, os.dup(self.fd)

    def lend(self, index: int, nbytes: int) -> Loan:
        """Slot ``index``'s memory for a loaned array of ``nbytes`` (at LOAN_OFFSET)."""
        start = shm.HEADER_SIZE + index * self.slot_size + shm.LOAN_OFFSET
        return Loan(self, index, self.view[start:start + nbytes])

    def write_around(self, loan: Loan, head: bytes, tail: bytes) -> Tuple[int, int] | None:
        """Write a loaned array's message around it: ``head`` (the frame's length prefix and
        the fields before it) just below, ``tail`` just after; ``(length, offset)`` of the
        frame in its slot, or None when they do not fit."""
        n = len(loan.view)
        if len(head) > shm.LOAN_OFFSET or shm.LOAN_OFFSET + n + len(tail) > self.slot_size:
            return None
        base = shm.HEADER_SIZE + loan.index * self.slot_size
        start = base + shm.LOAN_OFFSET - len(head)
        self.view[start:base + shm.LOAN_OFFSET] = head
        end = base + shm.LOAN_OFFSET + n
        self.view[end:end + len(tail)] = tail
        return len(head) + n + len(tail), start - base

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


class Memory:
    """One connection's shared memory at the publisher: its segment (a new, larger one when a
    frame does not fit: the SEGM announcement, with its descriptor, waits in ``control``),
    and which of its slots are free, written, queued or the subscriber's (``slots``)."""

    def __init__(self, topic: str, control: List[Tuple[bytes, int]]) -> None:
        self.topic = topic
        self.segment: ShmSegment | None = None
        self.slots = shm.SlotTable()
        #: the connection's records to send before any other (SEGM here, FALL), with the
        #: descriptor each carries (the sender's list, changed in place)
        self.control = control

    def fit(self, size: int) -> bool:
        """Make the segment's slots hold ``size`` bytes: True when that took a new segment
        (every slot free; the old one's announcement unsent is dropped), False when they did.
        OSError when the kernel refuses the memory."""
        seg = self.segment
        if seg is not None and size <= seg.slot_size:
            return False
        new = ShmSegment.for_frame(self.topic, size, seg)
        self.slots.resize(new.slots, new.generation)
        self.close_control()
        self.control.append(new.announcement())
        self.segment = new
        if seg is not None:
            seg.close()  # the subscriber's mapping keeps what it still reads
        return True

    def slot(self) -> int | None:
        """A free slot, being written from now, its memory allocated (None: none is free).
        OSError when the memory is not there."""
        index = self.slots.acquire()
        if index is None or self.segment is None:
            return None
        try:
            self.segment.prepare(index)
        except OSError:
            self.slots.abandon(index)
            raise
        return index

    def close_control(self) -> None:
        for _record, fd in self.control:
            if fd >= 0:
                os.close(fd)
        self.control.clear()

    def close(self) -> None:
        self.close_control()
        seg, self.segment = self.segment, None
        if seg is not None:
            seg.close()


class Loan:
    """A slot lent to the publisher: ``view`` is the writable memory of the array it fills."""

    __slots__ = ("segment", "index", "view")

    def __init__(self, segment: ShmSegment, index: int, view: memoryview) -> None:
        self.segment = segment
        self.index = index
        self.view = view


class Mapping:
    """A segment mapped read-only by the subscriber (it owns and closes ``fd``)."""

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
            raise shm.ShmError(f"cannot map the segment: {why(exc)}") from None
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
