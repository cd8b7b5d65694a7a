"""The RTPS message without I/O: the header, every submessage DDS peers send, and their builders.

One UDP datagram is one RTPS message (DDSI-RTPS 2.5, section 8.3 and 9.4)::

    "RTPS" | version 2.x | vendor id (2) | GUID prefix of the sender (12)      20 bytes
    then submessages, each: id (1) | flags (1) | octetsToNextHeader (2) | body

Flag bit 0 of every submessage is its byte order (1: little-endian). Some submessages carry the
information the ones after them need (INFO_TS: the source time of the next DATA; INFO_DST:
which participant the rest is for; INFO_SRC: another sender), the others are about one writer
and one reader each (``readerId``/``writerId``: entity ids of the destination participant and
of the sender). :func:`parse_message` applies the INFO submessages as the spec's "message
receiver" does and hands each entity submessage its context (``src``, ``dst``, ``timestamp``).

A peer's datagram is trusted for nothing: every announced length is checked against what is
there before anything is sliced, a sequence-number set holds at most 256 bits, a payload is a
``memoryview`` of the datagram (no copy; the caller copies what it keeps). A submessage that
does not add up ends the parse of that datagram (what came before it stands) and is reported
in :attr:`Message.error`; a bad header raises :class:`MalformedMessage`. Nothing else escapes.

The builders write little-endian submessages as bytes; a DATA's payload is not copied into
them but sent after them as a buffer of its own (``sendmsg``).
"""

from __future__ import annotations

import struct
from typing import List, Optional, Sequence, Tuple, Union

from minros.ros2.rtps.guid import VENDOR_MINROS

__all__ = [
    "ACKNACK", "AckNack", "DATA", "DATA_FRAG", "Data", "DataFrag", "GAP", "Gap", "HEADER_SIZE",
    "HEARTBEAT", "HEARTBEAT_FRAG", "Heartbeat", "HeartbeatFrag", "INFO_DST", "INFO_SRC", "INFO_TS",
    "InfoDst", "InfoSrc", "InfoTs", "MalformedMessage", "Message", "NACK_FRAG", "NackFrag", "PAD",
    "PROTOCOL_VERSION", "SN_UNKNOWN", "acknack", "data", "data_frag", "gap", "header", "heartbeat",
    "heartbeat_frag", "info_dst", "info_ts", "nack_frag", "parse_message", "time_from_ns",
    "time_to_ns",
]

Buffer = Union[bytes, bytearray, memoryview]

#: the version minros writes in its header (Fast DDS 2.14 and 3.2 write 2.2, Cyclone 2.5 or
#: 2.1; each accepts any 2.x)
PROTOCOL_VERSION = (2, 4)
HEADER_SIZE = 20

# submessage ids (RTPS 2.5 table 9.5); 0x80-0xff are vendor-specific (Fast DDS appends its
# statistics submessage 0x80 to every datagram: skipped like any id not listed here)
PAD = 0x01
ACKNACK = 0x06
HEARTBEAT = 0x07
GAP = 0x08
INFO_TS = 0x09
INFO_SRC = 0x0C
INFO_REPLY_IP4 = 0x0D
INFO_DST = 0x0E
INFO_REPLY = 0x0F
NACK_FRAG = 0x12
HEARTBEAT_FRAG = 0x13
DATA = 0x15
DATA_FRAG = 0x16

#: SEQUENCENUMBER_UNKNOWN: high -1, low 0
SN_UNKNOWN = -(1 << 32)
#: the largest set of sequence or fragment numbers a submessage may carry (RTPS 9.4.2.6)
MAX_SET_BITS = 256

_E = 0x01  # endianness flag, every submessage


class MalformedMessage(ValueError):
    """A datagram that is not an RTPS message; ``str()`` says what was wrong with it."""


# -- struct layouts, little- and big-endian ([0] big, [1] little, indexed by the E flag) ------

def _pair(fmt: str) -> Tuple[struct.Struct, struct.Struct]:
    return struct.Struct(">" + fmt), struct.Struct("<" + fmt)


_U16 = _pair("H")
_DATA = _pair("HH4s4siI")            # extraFlags, octetsToInlineQos, readerId, writerId, sn
_DATA_FRAG = _pair("HH4s4siIIHHI")   # ... fragmentStartingNum, fragmentsInSubmessage,
#                                      fragmentSize, sampleSize
_HEARTBEAT = _pair("4s4siIiIi")      # readerId, writerId, firstSN, lastSN, count
_HEARTBEAT_FRAG = _pair("4s4siIIi")  # readerId, writerId, writerSN, lastFragmentNum, count
_IDS = _pair("4s4s")
_SNSET_HEAD = _pair("iII")           # bitmapBase (high, low), numBits
_FNSET_HEAD = _pair("II")            # bitmapBase, numBits
_SN = _pair("iI")
_I32 = _pair("i")
_TIME = _pair("iI")
_PL_HEAD = _pair("HH")


def time_to_ns(seconds: int, fraction: int) -> int:
    """An RTPS Time_t (seconds, 2^-32 fractions) as nanoseconds."""
    return seconds * 1_000_000_000 + (fraction * 1_000_000_000 >> 32)


def time_from_ns(ns: int) -> Tuple[int, int]:
    seconds, rest = divmod(ns, 1_000_000_000)
    return seconds, (rest << 32) // 1_000_000_000


# -- the submessages, as parsed ---------------------------------------------------------------

class Submessage:
    """What every parsed submessage has: its id, flags, and the receiver's context."""

    __slots__ = ("flags", "src", "vendor", "dst", "timestamp")
    kind = 0

    def __init__(self) -> None:
        self.flags = 0
        #: the GUID prefix of the participant that sent it (the header's, or INFO_SRC's)
        self.src = b""
        self.vendor = b""
        #: the participant it is for (INFO_DST), or None: any
        self.dst: Optional[bytes] = None
        #: source time in ns (INFO_TS), or None
        self.timestamp: Optional[int] = None

    def __repr__(self) -> str:
        fields = ", ".join(f"{k}={getattr(self, k)!r}" for k in self.__slots__
                           if not isinstance(getattr(self, k), memoryview))
        return f"{type(self).__name__}({fields})"


class Data(Submessage):
    """DATA: one sample (or a key-only change) of writer ``writer_id``, sequence number ``sn``."""

    __slots__ = ("reader_id", "writer_id", "sn", "inline_qos", "payload", "key")
    kind = DATA

    def __init__(self, reader_id: bytes, writer_id: bytes, sn: int,
                 inline_qos: Optional[memoryview], payload: Optional[memoryview],
                 key: bool) -> None:
        super().__init__()
        self.reader_id = reader_id
        self.writer_id = writer_id
        self.sn = sn
        #: the inline QoS parameter list (raw, without its sentinel), or None
        self.inline_qos = inline_qos
        #: the serialized payload (its 4-byte encapsulation header first), or None
        self.payload = payload
        #: the payload is the serialized key, not the data (flag K)
        self.key = key


class DataFrag(Submessage):
    """DATA_FRAG: fragments ``start`` .. ``start + count - 1`` (1-based) of sample ``sn``."""

    __slots__ = ("reader_id", "writer_id", "sn", "start", "count", "fragment_size",
                 "sample_size", "inline_qos", "payload", "key")
    kind = DATA_FRAG

    def __init__(self, reader_id: bytes, writer_id: bytes, sn: int, start: int, count: int,
                 fragment_size: int, sample_size: int, inline_qos: Optional[memoryview],
                 payload: memoryview, key: bool) -> None:
        super().__init__()
        self.reader_id = reader_id
        self.writer_id = writer_id
        self.sn = sn
        self.start = start
        self.count = count
        self.fragment_size = fragment_size
        self.sample_size = sample_size
        self.inline_qos = inline_qos
        self.payload = payload
        self.key = key

    @property
    def total(self) -> int:
        """How many fragments the whole sample has."""
        return -(-self.sample_size // self.fragment_size)


class Heartbeat(Submessage):
    """HEARTBEAT: the writer has samples ``first`` .. ``last`` (``last = first - 1``: none)."""

    __slots__ = ("reader_id", "writer_id", "first", "last", "count")
    kind = HEARTBEAT

    def __init__(self, reader_id: bytes, writer_id: bytes, first: int, last: int,
                 count: int) -> None:
        super().__init__()
        self.reader_id = reader_id
        self.writer_id = writer_id
        self.first = first
        self.last = last
        self.count = count

    @property
    def final(self) -> bool:
        """F: the writer does not ask for an answer."""
        return bool(self.flags & 0x02)

    @property
    def liveliness(self) -> bool:
        return bool(self.flags & 0x04)


class HeartbeatFrag(Submessage):
    """HEARTBEAT_FRAG: fragments 1 .. ``last_fragment`` of sample ``sn`` have been sent."""

    __slots__ = ("reader_id", "writer_id", "sn", "last_fragment", "count")
    kind = HEARTBEAT_FRAG

    def __init__(self, reader_id: bytes, writer_id: bytes, sn: int, last_fragment: int,
                 count: int) -> None:
        super().__init__()
        self.reader_id = reader_id
        self.writer_id = writer_id
        self.sn = sn
        self.last_fragment = last_fragment
        self.count = count


class AckNack(Submessage):
    """ACKNACK: the reader has everything before ``base`` and misses ``missing``."""

    __slots__ = ("reader_id", "writer_id", "base", "missing", "count")
    kind = ACKNACK

    def __init__(self, reader_id: bytes, writer_id: bytes, base: int, missing: Tuple[int, ...],
                 count: int) -> None:
        super().__init__()
        self.reader_id = reader_id
        self.writer_id = writer_id
        self.base = base
        self.missing = missing
        self.count = count

    @property
    def final(self) -> bool:
        return bool(self.flags & 0x02)


class NackFrag(Submessage):
    """NACK_FRAG: of sample ``sn`` the reader misses fragments ``missing`` (1-based)."""

    __slots__ = ("reader_id", "writer_id", "sn", "base", "missing", "count")
    kind = NACK_FRAG

    def __init__(self, reader_id: bytes, writer_id: bytes, sn: int, base: int,
                 missing: Tuple[int, ...], count: int) -> None:
        super().__init__()
        self.reader_id = reader_id
        self.writer_id = writer_id
        self.sn = sn
        self.base = base
        self.missing = missing
        self.count = count


class Gap(Submessage):
    """GAP: samples ``start`` .. ``list_base - 1`` and those in ``members`` will never come."""

    __slots__ = ("reader_id", "writer_id", "start", "list_base", "members")
    kind = GAP

    def __init__(self, reader_id: bytes, writer_id: bytes, start: int, list_base: int,
                 members: Tuple[int, ...]) -> None:
        super().__init__()
        self.reader_id = reader_id
        self.writer_id = writer_id
        self.start = start
        self.list_base = list_base
        self.members = members

    def irrelevant(self) -> List[int]:
        """Every sequence number the GAP names (at most ``list_base - start`` + 256)."""
        return [*range(self.start, self.list_base), *self.members]


class InfoTs(Submessage):
    __slots__ = ("time",)
    kind = INFO_TS

    def __init__(self, time: Optional[int]) -> None:
        super().__init__()
        self.time = time


class InfoDst(Submessage):
    __slots__ = ("prefix",)
    kind = INFO_DST

    def __init__(self, prefix: bytes) -> None:
        super().__init__()
        self.prefix = prefix


class InfoSrc(Submessage):
    __slots__ = ("prefix", "source_vendor")
    kind = INFO_SRC

    def __init__(self, prefix: bytes, source_vendor: bytes) -> None:
        super().__init__()
        self.prefix = prefix
        self.source_vendor = source_vendor


class Message:
    """One parsed datagram: its header, its submessages in order, and why the parse stopped
    early (``error``), if it did."""

    __slots__ = ("version", "vendor", "prefix", "submessages", "error")

    def __init__(self, version: Tuple[int, int], vendor: bytes, prefix: bytes) -> None:
        self.version = version
        self.vendor = vendor
        self.prefix = prefix
        self.submessages: List[Submessage] = []
        self.error: Optional[str] = None


# -- parsing ----------------------------------------------------------------------------------

def parse_message(buf: Buffer) -> Message:
    """Parse one datagram. Raises MalformedMessage for a header that is not RTPS 2.x; a bad
    submessage stops the parse there (``Message.error``), keeping the ones before it."""
    mv = memoryview(buf)
    if mv.ndim != 1 or mv.itemsize != 1:
        mv = mv.cast("B")
    n = len(mv)
    if n < HEADER_SIZE:
        raise MalformedMessage(f"{n} bytes: shorter than an RTPS header (20 bytes)")
    if bytes(mv[:4]) != b"RTPS":
        raise MalformedMessage("not an RTPS message (it does not start with 'RTPS')")
    if mv[4] != 2:
        raise MalformedMessage(f"RTPS version {mv[4]}.{mv[5]}: only 2.x is spoken here")
    msg = Message((mv[4], mv[5]), bytes(mv[6:8]), bytes(mv[8:20]))
    src, vendor = msg.prefix, msg.vendor
    dst: Optional[bytes] = None
    timestamp: Optional[int] = None
    pos = HEADER_SIZE
    out = msg.submessages
    while pos < n:
        if n - pos < 4:
            msg.error = f"submessage header cut short at byte {pos}"
            break
        sid = mv[pos]
        flags = mv[pos + 1]
        le = flags & _E
        (length,) = _U16[le].unpack_from(mv, pos + 2)
        body = pos + 4
        if length == 0 and sid not in (PAD, INFO_TS):
            end = n  # the last submessage may say 0: it runs to the end of the message
        else:
            end = body + length
            if end > n:
                msg.error = (f"submessage 0x{sid:02x} at byte {pos} announces {length} bytes, "
                             f"{n - body} are there")
                break
        try:
            sub = _parse_submessage(sid, flags, le, mv, body, end)
        except (struct.error, ValueError, IndexError) as exc:
            msg.error = f"submessage 0x{sid:02x} at byte {pos}: {exc}"
            break
        pos = end
        if sub is None:
            continue
        kind = sub.kind
        if kind == INFO_TS:
            timestamp = sub.time  # type: ignore[attr-defined]
        elif kind == INFO_DST:
            prefix = sub.prefix  # type: ignore[attr-defined]
            dst = None if prefix == bytes(12) else prefix
        elif kind == INFO_SRC:
            src = sub.prefix  # type: ignore[attr-defined]
            vendor = sub.source_vendor  # type: ignore[attr-defined]
            dst, timestamp = None, None
        sub.flags = flags
        sub.src = src
        sub.vendor = vendor
        sub.dst = dst
        sub.timestamp = timestamp
        out.append(sub)
    return msg


def _check(condition: bool, what: str) -> None:
    if not condition:
        raise ValueError(what)


def _sn_set(mv: memoryview, pos: int, end: int, le: int) -> Tuple[int, Tuple[int, ...], int]:
    """A SequenceNumberSet at ``pos``: (base, members, position after it)."""
    hi, lo, nbits = _SNSET_HEAD[le].unpack_from(mv, pos)
    _check(nbits <= MAX_SET_BITS, f"a set of {nbits} bits (at most 256)")
    base = (hi << 32) | lo
    _check(base >= 0, f"a set based at {base}")
    words = (nbits + 31) >> 5
    pos += 12
    _check(pos + 4 * words <= end, "a set's bitmap runs past its submessage")
    return base, _members(mv, pos, words, nbits, le, base), pos + 4 * words


def _fn_set(mv: memoryview, pos: int, end: int, le: int) -> Tuple[int, Tuple[int, ...], int]:
    base, nbits = _FNSET_HEAD[le].unpack_from(mv, pos)
    _check(nbits <= MAX_SET_BITS, f"a set of {nbits} bits (at most 256)")
    _check(base >= 1, f"a fragment set based at {base}")
    words = (nbits + 31) >> 5
    pos += 8
    _check(pos + 4 * words <= end, "a set's bitmap runs past its submessage")
    return base, _members(mv, pos, words, nbits, le, base), pos + 4 * words


def _members(mv: memoryview, pos: int, words: int, nbits: int, le: int,
             base: int) -> Tuple[int, ...]:
    if not words:
        return ()
    bitmap = struct.unpack_from(("<" if le else ">") + "I" * words, mv, pos)
    out: List[int] = []
    for w, word in enumerate(bitmap):
        if not word:
            continue
        first = w << 5
        for bit in range(min(32, nbits - first)):
            if word & (0x80000000 >> bit):
                out.append(base + first + bit)
    return tuple(out)


def _param_list_end(mv: memoryview, pos: int, end: int, le: int) -> int:
    """Where the parameter list at ``pos`` ends (after its sentinel)."""
    head = _PL_HEAD[le]
    while True:
        _check(pos + 4 <= end, "a parameter list without its sentinel")
        pid, plen = head.unpack_from(mv, pos)
        pos += 4
        if pid == 0x0001:
            return pos
        _check(pos + plen <= end, f"parameter 0x{pid:04x} announces {plen} bytes past its end")
        pos += plen


def _trim_padding(payload: memoryview) -> memoryview:
    """A payload without the padding its encapsulation options say it ends with."""
    if len(payload) >= 4:
        padding = payload[3] & 0x03
        if padding and len(payload) - padding >= 4:
            return payload[:len(payload) - padding]
    return payload


def _parse_submessage(sid: int, flags: int, le: int, mv: memoryview, body: int,
                      end: int) -> Optional[Submessage]:
    if sid == DATA:
        _check(end - body >= 20, "a DATA shorter than its fixed part")
        _, oti, rid, wid, hi, lo = _DATA[le].unpack_from(mv, body)
        pos = body + 4 + oti
        _check(pos <= end, f"octetsToInlineQos {oti} runs past the DATA")
        qos = None
        if flags & 0x02:
            qend = _param_list_end(mv, pos, end, le)
            qos = mv[pos:qend - 4]
            pos = qend
        payload = None
        if flags & 0x0C:  # D (data) or K (key)
            _check(end - pos >= 4, "a DATA payload without its encapsulation header")
            payload = _trim_padding(mv[pos:end])
        return Data(rid, wid, (hi << 32) | lo, qos, payload, bool(flags & 0x08))
    if sid == DATA_FRAG:
        _check(end - body >= 32, "a DATA_FRAG shorter than its fixed part")
        _, oti, rid, wid, hi, lo, start, count, fsize, ssize = _DATA_FRAG[le].unpack_from(mv, body)
        _check(start >= 1 and count >= 1 and fsize >= 1,
               f"fragments {start}+{count} of size {fsize}")
        _check((start - 1) * fsize < ssize, f"fragment {start} of {fsize} bytes beyond a "
                                            f"{ssize}-byte sample")
        pos = body + 4 + oti
        _check(pos <= end, f"octetsToInlineQos {oti} runs past the DATA_FRAG")
        qos = None
        if flags & 0x02:
            qend = _param_list_end(mv, pos, end, le)
            qos = mv[pos:qend - 4]
            pos = qend
        want = min(count * fsize, ssize - (start - 1) * fsize)
        _check(end - pos >= want, f"{count} fragments of {fsize} bytes in {end - pos} bytes")
        return DataFrag(rid, wid, (hi << 32) | lo, start, count, fsize, ssize, qos,
                        mv[pos:pos + want], bool(flags & 0x04))
    if sid == HEARTBEAT:
        rid, wid, fh, fl, lh, ll, count = _HEARTBEAT[le].unpack_from(mv, body)
        first, last = (fh << 32) | fl, (lh << 32) | ll
        _check(first >= 1 and last >= first - 1, f"a HEARTBEAT of {first}..{last}")
        return Heartbeat(rid, wid, first, last, count)
    if sid == ACKNACK:
        rid, wid = _IDS[le].unpack_from(mv, body)
        base, missing, pos = _sn_set(mv, body + 8, end, le)
        (count,) = _I32[le].unpack_from(mv, pos)
        return AckNack(rid, wid, base, missing, count)
    if sid == GAP:
        rid, wid = _IDS[le].unpack_from(mv, body)
        hi, lo = _SN[le].unpack_from(mv, body + 8)
        start = (hi << 32) | lo
        base, members, _ = _sn_set(mv, body + 16, end, le)
        _check(start >= 1 and base >= start, f"a GAP from {start} to {base}")
        return Gap(rid, wid, start, base, members)
    if sid == NACK_FRAG:
        rid, wid = _IDS[le].unpack_from(mv, body)
        hi, lo = _SN[le].unpack_from(mv, body + 8)
        base, missing, pos = _fn_set(mv, body + 16, end, le)
        (count,) = _I32[le].unpack_from(mv, pos)
        return NackFrag(rid, wid, (hi << 32) | lo, base, missing, count)
    if sid == HEARTBEAT_FRAG:
        rid, wid, hi, lo, last, count = _HEARTBEAT_FRAG[le].unpack_from(mv, body)
        return HeartbeatFrag(rid, wid, (hi << 32) | lo, last, count)
    if sid == INFO_TS:
        if flags & 0x02:  # I: invalidate
            return InfoTs(None)
        sec, frac = _TIME[le].unpack_from(mv, body)
        return InfoTs(time_to_ns(sec, frac))
    if sid == INFO_DST:
        _check(end - body >= 12, "an INFO_DST shorter than a GUID prefix")
        return InfoDst(bytes(mv[body:body + 12]))
    if sid == INFO_SRC:
        _check(end - body >= 20, "an INFO_SRC shorter than 20 bytes")
        return InfoSrc(bytes(mv[body + 8:body + 20]), bytes(mv[body + 6:body + 8]))
    return None  # PAD, INFO_REPLY, vendor-specific and unknown ids: skipped


# -- building ---------------------------------------------------------------------------------

_LE_DATA = struct.Struct("<BBHHH4s4siI")
_LE_DATA_FRAG = struct.Struct("<BBHHH4s4siIIHHI")
_LE_HEARTBEAT = struct.Struct("<BBH4s4siIiIi")
_LE_HEARTBEAT_FRAG = struct.Struct("<BBH4s4siIIi")
_LE_SUBHEAD = struct.Struct("<BBH")
_LE_TIME = struct.Struct("<BBHiI")


def header(prefix: bytes, vendor: bytes = VENDOR_MINROS) -> bytes:
    """The 20-byte message header of participant ``prefix``."""
    return b"RTPS" + bytes(PROTOCOL_VERSION) + bytes(vendor) + bytes(prefix)


def info_dst(prefix: bytes) -> bytes:
    return _LE_SUBHEAD.pack(INFO_DST, _E, 12) + bytes(prefix)


def info_ts(ns: Optional[int]) -> bytes:
    """INFO_TS with the source time ``ns`` (None: invalidate, no time)."""
    if ns is None:
        return _LE_SUBHEAD.pack(INFO_TS, _E | 0x02, 0)
    sec, frac = time_from_ns(ns)
    return _LE_TIME.pack(INFO_TS, _E, 8, sec, frac)


def _sn(sn: int) -> Tuple[int, int]:
    return sn >> 32, sn & 0xFFFFFFFF


def data(reader_id: bytes, writer_id: bytes, sn: int, payload_size: int,
         inline_qos: bytes = b"", key: bool = False) -> Tuple[bytes, bytes]:
    """A DATA submessage without its payload: (the bytes before the payload, the padding after
    it). ``inline_qos`` is a parameter list with its sentinel; ``payload_size`` 0 is no payload
    (a change carried by the inline QoS alone)."""
    pad = b"\0" * (-payload_size % 4)
    flags = _E | (0x02 if inline_qos else 0)
    if payload_size:
        flags |= 0x08 if key else 0x04
    length = 20 + len(inline_qos) + payload_size + len(pad)
    _check(length <= 0xFFFF, f"a DATA of {length} bytes: fragment it (DATA_FRAG)")
    hi, lo = _sn(sn)
    return _LE_DATA.pack(DATA, flags, length, 0, 16, reader_id, writer_id, hi, lo) + inline_qos, pad


def data_frag(reader_id: bytes, writer_id: bytes, sn: int, start: int, count: int,
              fragment_size: int, sample_size: int, payload_size: int,
              inline_qos: bytes = b"") -> Tuple[bytes, bytes]:
    """A DATA_FRAG carrying fragments ``start`` .. ``start + count - 1`` (``payload_size``
    bytes of them), without those bytes: (before, padding after)."""
    pad = b"\0" * (-payload_size % 4)
    flags = _E | (0x02 if inline_qos else 0)
    length = 32 + len(inline_qos) + payload_size + len(pad)
    _check(length <= 0xFFFF, f"a DATA_FRAG of {length} bytes")
    hi, lo = _sn(sn)
    return _LE_DATA_FRAG.pack(DATA_FRAG, flags, length, 0, 28, reader_id, writer_id, hi, lo,
                              start, count, fragment_size, sample_size) + inline_qos, pad


def heartbeat(reader_id: bytes, writer_id: bytes, first: int, last: int, count: int,
              final: bool = False, liveliness: bool = False) -> bytes:
    flags = _E | (0x02 if final else 0) | (0x04 if liveliness else 0)
    fh, fl = _sn(first)
    lh, ll = _sn(last)
    return _LE_HEARTBEAT.pack(HEARTBEAT, flags, 28, reader_id, writer_id, fh, fl, lh, ll, count)


def heartbeat_frag(reader_id: bytes, writer_id: bytes, sn: int, last_fragment: int,
                   count: int) -> bytes:
    hi, lo = _sn(sn)
    return _LE_HEARTBEAT_FRAG.pack(HEARTBEAT_FRAG, _E, 24, reader_id, writer_id, hi, lo,
                                   last_fragment, count)


def _bitmap(base: int, members: Sequence[int]) -> Tuple[int, bytes]:
    if not members:
        return 0, b""
    nbits = max(members) - base + 1
    _check(min(members) >= base and nbits <= MAX_SET_BITS,
           f"members {min(members)}..{max(members)} do not fit a set based at {base}")
    words = [0] * ((nbits + 31) >> 5)
    for m in members:
        i = m - base
        words[i >> 5] |= 0x80000000 >> (i & 31)
    return nbits, struct.pack("<" + "I" * len(words), *words)


def acknack(reader_id: bytes, writer_id: bytes, base: int, missing: Sequence[int], count: int,
            final: bool = False) -> bytes:
    """ACKNACK: everything before ``base`` received, ``missing`` (each in base..base+255)
    asked for again."""
    nbits, bitmap = _bitmap(base, missing)
    hi, lo = _sn(base)
    body = (bytes(reader_id) + bytes(writer_id) + struct.pack("<iII", hi, lo, nbits) + bitmap
            + struct.pack("<i", count))
    return _LE_SUBHEAD.pack(ACKNACK, _E | (0x02 if final else 0), len(body)) + body


def nack_frag(reader_id: bytes, writer_id: bytes, sn: int, base: int, missing: Sequence[int],
              count: int) -> bytes:
    nbits, bitmap = _bitmap(base, missing)
    hi, lo = _sn(sn)
    body = (bytes(reader_id) + bytes(writer_id) + struct.pack("<iIII", hi, lo, base, nbits)
            + bitmap + struct.pack("<i", count))
    return _LE_SUBHEAD.pack(NACK_FRAG, _E, len(body)) + body


def gap(reader_id: bytes, writer_id: bytes, start: int, list_base: int,
        members: Sequence[int] = ()) -> bytes:
    """GAP: ``start`` .. ``list_base - 1`` and ``members`` are irrelevant to the reader."""
    nbits, bitmap = _bitmap(list_base, members)
    sh, sl = _sn(start)
    bh, bl = _sn(list_base)
    body = (bytes(reader_id) + bytes(writer_id) + struct.pack("<iIiII", sh, sl, bh, bl, nbits)
            + bitmap)
    return _LE_SUBHEAD.pack(GAP, _E, len(body)) + body
