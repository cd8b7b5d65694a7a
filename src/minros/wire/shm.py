"""MINROSSHM, minros's same-host shared-memory protocol for topics, without I/O: the
``requestTopic`` offer and answer, the records both ends exchange, the segment's layout, and
the publisher's slot table. ``minros.transport.shm`` moves the bytes; everything a peer can
get wrong is checked here and raises :class:`ShmError` (the transport then falls back to
TCPROS).

Negotiation. A minros subscriber offers ``["MINROSSHM", 1, boot_id]`` first in requestTopic
and ``["TCPROS"]` second; rospy and roscpp skip a protocol they do not know, so they answer
TCPROS. A minros publisher takes the offer only from its own kernel (the same
``/proc/sys/kernel/random/boot_id``) and answers ``["MINROSSHM", name, boot_id]``: ``name`` is
an abstract Unix socket (Linux; no file to leave behind), reachable only from the same network
namespace, over which file descriptors pass only on the same kernel. So "same host" is checked
three times, never assumed; any failure falls back to TCPROS.

The connection. The subscriber connects to that socket and the two run the TCPROS connection
header exchange on it (``wire/handshake``). Then the publisher sends records; each starts with
a 4-byte ASCII tag:

====== ============================================= =========================================
tag    fields (little-endian)                        meaning
====== ============================================= =========================================
SEGM   u32 generation, u32 slots, u32 slot_size,     a new segment: the memfd travels with this
       u64 size                                      record (SCM_RIGHTS); older ones retire
SLOT   u32 generation, u32 slot, u32 offset,         a message: the TCPROS frame (its length
       u32 length, u64 seq                           prefix included) at ``offset`` in ``slot``
MSG_   a TCPROS frame (u32 length, body)             a small message, inline (``MSG `` )
FALL   u32 length, UTF-8 reason                      shared memory failed here: use TCPROS
====== ============================================= =========================================

and the subscriber answers each SLOT with ``DONE`` (u32 generation, u32 slot) once its
callbacks returned: the slot is the publisher's again. Messages smaller than ``INLINE_LIMIT``
go inline, so small messages cost what they cost over TCPROS (one send, one receive).

The segment: a header page (``SEGMENT_MAGIC``, version, generation, slots, slot_size), then
``slots`` slots of ``slot_size`` bytes (page multiples), sized from the first large message
(a larger one later makes a new segment, half as large again). A publisher's segment has
``SLOTS`` = ``WINDOW`` + 1 = 3 slots whatever its queue_size: ``WINDOW`` = 2 in the
subscriber's hands at most, one written ahead. The frames queued behind them wait at the
publisher as frames, shared with every other connection as over TCPROS, and are copied into a
slot only when one is free; so a subscriber that reads nothing holds three slots of the
publisher's memory, never its whole queue.

The memfd passed with SEGM is sealed against writes by anyone but the publisher's own mapping
(``F_SEAL_FUTURE_WRITE``: no new writable mapping, no ``write(2)``, through whatever descriptor
or reopened ``/proc`` path), and the descriptor itself is opened read-only: a subscriber cannot
change what the others read.
"""

from __future__ import annotations

import struct
from typing import Any, Dict, List, Optional, Set, Tuple, Union

__all__ = [
    "BOOT_ID_PATH", "DONE", "FALL", "HEADER_SIZE", "INLINE", "INLINE_LIMIT", "LOAN_OFFSET",
    "LOAN_TAIL", "MAX_SLOTS", "PROTOCOL", "SEGM", "SEGMENT_MAGIC", "SLOT", "SLOTS", "VERSION",
    "WINDOW", "Done", "DoneReader", "Fallback", "NoticeReader", "Segment", "ShmError", "Slot",
    "SlotTable", "answer", "check_offer", "check_segment_header", "done", "fallback",
    "grown_slot_size", "inline_head", "offer", "page_round", "parse_answer", "segment",
    "segment_header", "slot",
]

#: the protocol's name in requestTopic
PROTOCOL = "MINROSSHM"
#: the version a subscriber offers and a publisher checks
VERSION = 1
BOOT_ID_PATH = "/proc/sys/kernel/random/boot_id"

#: messages whose frame is smaller go inline (one send, one receive, as over TCPROS)
INLINE_LIMIT = 64 << 10
#: slots the subscriber may hold at once (notified and not DONE)
WINDOW = 2
#: the slots of a publisher's segment: the window and one written ahead
SLOTS = WINDOW + 1
#: the most slots a segment may announce (a subscriber refuses more)
MAX_SLOTS = 64
#: the segment's first page: its header
HEADER_SIZE = 4096
PAGE = 4096
#: where a loaned array starts in its slot (``Publisher.loan``): the fields before it are
#: written just below, the ones after it just after it
LOAN_OFFSET = 4096
#: room a loaned slot keeps for the fields after the array
LOAN_TAIL = 4096
#: the longest reason a FALL record may carry
REASON_LIMIT = 1024
#: the longest name an answer may give for the publisher's socket
NAME_LIMIT = 100

SEGM, SLOT, INLINE, FALL, DONE = b"SEGM", b"SLOT", b"MSG ", b"FALL", b"DONE"
SEGMENT_MAGIC = b"MINROSHM"

_SEGM = struct.Struct("<4sIIIQ")
_SLOT = struct.Struct("<4sIIIIQ")
_U32 = struct.Struct("<I")
_HEAD = struct.Struct("<4sI")  # a record's tag and its first u32
_DONE = struct.Struct("<4sII")
_HEADER = struct.Struct("<8sIIIIQ")  # magic, version, generation, slots, (zero), slot_size


class ShmError(ValueError):
    """A peer broke the shared-memory protocol (the connection falls back to TCPROS)."""


# --------------------------------------------------------------------------- negotiation


def offer(boot_id: str) -> List[Any]:
    """The subscriber's entry in requestTopic's protocol list."""
    return [PROTOCOL, VERSION, boot_id]


def check_offer(offer: List[Any], boot_id: str) -> Optional[str]:
    """Why a publisher whose kernel is ``boot_id`` declines ``offer`` (None: it takes it)."""
    if len(offer) < 3 or offer[0] != PROTOCOL:
        return "not a MINROSSHM offer"
    version, peer = offer[1], offer[2]
    if not isinstance(version, int) or isinstance(version, bool) or version != VERSION:
        return f"version {version!r} (this publisher speaks {VERSION})"
    if not isinstance(peer, str) or not peer or not boot_id or peer != boot_id:
        return "another host (its boot id differs)"
    return None


def answer(name: str, boot_id: str) -> List[Any]:
    """The publisher's answer: its abstract socket's name (without the leading NUL)."""
    return [PROTOCOL, name, boot_id]


def parse_answer(answer: List[Any], boot_id: str) -> str:
    """The socket name of a publisher's answer; ValueError for one a subscriber cannot use."""
    if (len(answer) != 3 or answer[0] != PROTOCOL or not isinstance(answer[1], str)
            or not answer[1] or len(answer[1]) > NAME_LIMIT or "\0" in answer[1]):
        raise ValueError(f"publisher returned invalid protocol choice: {answer}")
    if answer[2] != boot_id:
        raise ValueError("publisher answered MINROSSHM from another host")
    return answer[1]


# --------------------------------------------------------------------------- sizes


def page_round(size: int) -> int:
    return (size + PAGE - 1) // PAGE * PAGE


def grown_slot_size(needed: int, current: int = 0) -> int:
    """The slot size for a frame of ``needed`` bytes: that frame's size rounded to pages the
    first time (``current`` 0), then at least half as large again, so that a stream of
    growing messages makes few segments."""
    if not current:
        return page_round(needed)
    return page_round(max(needed, current + current // 2))


# --------------------------------------------------------------------------- the segment


def segment_header(generation: int, slots: int, slot_size: int) -> bytes:
    return _HEADER.pack(SEGMENT_MAGIC, VERSION, generation, slots, 0, slot_size)


def check_segment_header(data: Any, seg: Segment) -> None:
    """The header page of a mapped segment must say what its SEGM record said."""
    try:
        magic, version, generation, slots, _zero, slot_size = _HEADER.unpack_from(data, 0)
    except struct.error:
        raise ShmError("the segment is too small for its header") from None
    if magic != SEGMENT_MAGIC or version != VERSION:
        raise ShmError("the file passed is not a MINROSSHM segment")
    if (generation, slots, slot_size) != (seg.generation, seg.slots, seg.slot_size):
        raise ShmError(f"the segment's header (generation {generation}, {slots} slots of "
                       f"{slot_size} bytes) contradicts its announcement")


# --------------------------------------------------------------------------- records


class Segment(Tuple[int, int, int, int]):
    """SEGM: a new segment of ``slots`` slots of ``slot_size`` bytes, ``size`` in all."""

    __slots__ = ()
    generation = property(lambda self: self[0])
    slots = property(lambda self: self[1])
    slot_size = property(lambda self: self[2])
    size = property(lambda self: self[3])


class Slot(Tuple[int, int, int, int, int]):
    """SLOT: a frame of ``length`` bytes at ``offset`` in ``slot`` of segment ``generation``."""

    __slots__ = ()
    generation = property(lambda self: self[0])
    slot = property(lambda self: self[1])
    offset = property(lambda self: self[2])
    length = property(lambda self: self[3])
    seq = property(lambda self: self[4])


class Fallback(str):
    """FALL: the publisher gave up on shared memory, for this reason."""

    __slots__ = ()


class Done(Tuple[int, int]):
    """DONE: the subscriber is through with ``slot`` of segment ``generation``."""

    __slots__ = ()
    generation = property(lambda self: self[0])
    slot = property(lambda self: self[1])


#: what NoticeReader returns: records, and small messages' bodies as ``bytes`` (MSG)
Notice = Union[Segment, Slot, bytes, Fallback]


def segment(generation: int, slots: int, slot_size: int) -> bytes:
    return _SEGM.pack(SEGM, generation, slots, slot_size, HEADER_SIZE + slots * slot_size)


def slot(generation: int, index: int, offset: int, length: int, seq: int) -> bytes:
    return _SLOT.pack(SLOT, generation, index, offset, length, seq)


def inline_head() -> bytes:
    """What goes before a frame sent inline (the frame carries its own length prefix)."""
    return INLINE


def fallback(reason: str) -> bytes:
    data = reason.encode("utf-8", "replace")[:REASON_LIMIT]
    return FALL + _U32.pack(len(data)) + data


def done(generation: int, index: int) -> bytes:
    return _DONE.pack(DONE, generation, index)


class _Reader:
    """A buffer that records are cut from as bytes arrive (``recv_into(reader.space())``,
    then ``reader.received(n)``); its size bounds what a peer can make it hold."""

    def __init__(self, size: int) -> None:
        self.buf = bytearray(size)
        self.view = memoryview(self.buf)
        self.start = 0
        self.end = 0

    def space(self) -> memoryview:
        """Where the next bytes go (the unread rest moves to the front first)."""
        if self.start:
            if self.start == self.end:
                self.start = self.end = 0
            elif self.end > len(self.buf) // 2:
                rest = self.end - self.start
                self.buf[:rest] = self.view[self.start:self.end]
                self.start, self.end = 0, rest
        return self.view[self.end:]

    @property
    def pending(self) -> int:
        """Bytes of an incomplete record."""
        return self.end - self.start


class NoticeReader(_Reader):
    """The subscriber's reader of the publisher's records."""

    def __init__(self) -> None:
        # the largest record is an inline frame: room for two, so one always fits after a part
        super().__init__(2 * (INLINE_LIMIT + 8))

    def received(self, n: int) -> List[Notice]:
        """The records completed by ``n`` more bytes in ``space()``; ShmError on garbage."""
        self.end += n
        out: List[Notice] = []
        buf, view = self.buf, self.view
        end = self.end
        while True:
            start = self.start
            have = end - start
            if have < 8:
                break
            tag, size = _HEAD.unpack_from(buf, start)
            if tag == INLINE:
                if size + 4 > INLINE_LIMIT:
                    raise ShmError(f"an inline message of {size} bytes (the limit is "
                                   f"{INLINE_LIMIT - 4})")
                if have < 8 + size:
                    break
                out.append(bytes(view[start + 8:start + 8 + size]))
                self.start = start + 8 + size
            elif tag == SLOT:
                if have < _SLOT.size:
                    break
                _, generation, index, offset, length, seq = _SLOT.unpack_from(buf, start)
                out.append(Slot((generation, index, offset, length, seq)))
                self.start = start + _SLOT.size
            elif tag == SEGM:
                if have < _SEGM.size:
                    break
                _, generation, slots, slot_size, size = _SEGM.unpack_from(buf, start)
                if not 1 <= slots <= MAX_SLOTS or slot_size < PAGE or slot_size % PAGE:
                    raise ShmError(f"a segment of {slots} slots of {slot_size} bytes")
                if size != HEADER_SIZE + slots * slot_size:
                    raise ShmError(f"a segment of {size} bytes for {slots} slots of {slot_size}")
                out.append(Segment((generation, slots, slot_size, size)))
                self.start = start + _SEGM.size
            elif tag == FALL:
                (size,) = _U32.unpack_from(buf, start + 4)
                if size > REASON_LIMIT:
                    raise ShmError(f"a fallback reason of {size} bytes")
                if have < 8 + size:
                    break
                out.append(Fallback(bytes(view[start + 8:start + 8 + size]).decode(
                    "utf-8", "replace")))
                self.start = start + 8 + size
            else:
                raise ShmError(f"unknown record {tag!r}")
        return out


class DoneReader(_Reader):
    """The publisher's reader of the subscriber's DONE records."""

    def __init__(self) -> None:
        super().__init__(64 * _DONE.size)

    def received(self, n: int) -> List[Done]:
        self.end += n
        out: List[Done] = []
        while self.end - self.start >= _DONE.size:
            tag, generation, index = _DONE.unpack_from(self.buf, self.start)
            if tag != DONE:
                raise ShmError(f"unknown record {tag!r} from the subscriber")
            out.append(Done((generation, index)))
            self.start += _DONE.size
        return out


# --------------------------------------------------------------------------- the publisher's slots

FREE, WRITING, QUEUED, NOTIFIED = range(4)


class SlotTable:
    """The publisher's slots of one connection, without I/O: which are free, being written,
    queued (written, waiting to be announced) or in the subscriber's hands, of which at most
    ``window`` at once (announced with SLOT, not yet given back with DONE).

    What waits to be sent, and which of it is dropped, is the connection's queue
    (``minros.transport.sendqueue``, as over TCPROS); this table only says where a frame may
    be written and when it may be announced."""

    def __init__(self, slots: int = SLOTS, window: int = WINDOW, generation: int = 1) -> None:
        self.generation = generation
        self.state: List[int] = []
        self.window = window
        self.notified: Set[Tuple[int, int]] = set()  # (generation, slot), older ones included
        self.seq = 0
        self.resize(slots, generation)

    def resize(self, slots: int, generation: int) -> None:
        """A new segment: every slot is free (the subscriber still holds the notified slots
        of the old one, which count against the window)."""
        self.generation = generation
        self.state = [FREE] * slots

    @property
    def in_flight(self) -> int:
        return len(self.notified)

    def room(self) -> bool:
        """Whether one more slot may be announced now."""
        return len(self.notified) < self.window

    def acquire(self) -> Optional[int]:
        """A free slot to write a frame into (now being written), or None."""
        state = self.state
        for index, value in enumerate(state):
            if value == FREE:
                state[index] = WRITING
                return index
        return None

    def abandon(self, index: int) -> None:
        """A slot being written and not queued after all, or a queued one whose frame was
        dropped: free again."""
        if self.state[index] in (WRITING, QUEUED):
            self.state[index] = FREE

    def queued(self, index: int) -> None:
        """Slot ``index`` holds its frame and waits to be announced."""
        self.state[index] = QUEUED

    def announce(self, index: int, offset: int, length: int) -> bytes:
        """The SLOT record of queued slot ``index`` (``room()`` said so): the slot is the
        subscriber's until it says DONE."""
        self.state[index] = NOTIFIED
        self.notified.add((self.generation, index))
        self.seq += 1
        return slot(self.generation, index, offset, length, self.seq)

    def done(self, generation: int, index: int) -> None:
        """The subscriber is through with a slot; ShmError for one it does not hold."""
        key = (generation, index)
        if key not in self.notified:
            raise ShmError(f"DONE for slot {index} of generation {generation}, which the "
                           "subscriber does not hold")
        self.notified.discard(key)
        if generation == self.generation:
            self.state[index] = FREE

    def counts(self) -> Dict[str, int]:
        """How many slots are in each state (for tests and getBusInfo)."""
        names = ("free", "writing", "queued", "notified")
        return {names[s]: self.state.count(s) for s in range(4)}
