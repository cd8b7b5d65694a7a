"""The RTPS reader as a state machine without I/O: one proxy per matched writer, in-order
delivery, ACKNACK/NACK_FRAG answers to HEARTBEATs, GAPs, and bounded fragment reassembly.

A reliable reader delivers each writer's samples in sequence-number order, exactly once::

    DATA sn == next        -> delivered, and whatever was waiting behind it
    DATA sn >  next        -> kept until the gap before it is filled (or GAPed)
    DATA_FRAG              -> into that sample's reassembly; a whole sample is a DATA
    GAP                    -> those sequence numbers will never come: skipped
    HEARTBEAT (not final)  -> ACKNACK: "I have all before `next`, I miss these"; a half-received
                              sample is a NACK_FRAG of its missing fragments instead

A best-effort reader delivers what arrives if it is newer than what it delivered last.

A volatile reader starts at whatever the writer sends it first: its first DATA, or the end of
the first HEARTBEAT (it does not ask for history); a transient-local reader starts at the
HEARTBEAT's first sequence number and asks for everything from there.

**Bounds** (a writer cannot make the reader hold more): a sample larger than
``max_sample_size`` is refused at its first fragment; a writer has at most
``max_partial`` samples in reassembly (the oldest is dropped for a new one) and the reader's
partial samples hold at most ``max_partial_bytes`` *received* bytes together (large buffers
are anonymous memory maps, so what a peer only announces costs address space, not memory);
at most ``max_pending`` samples wait behind a gap, after which the reader gives up on the gap
(as a KEEP_LAST reader would have dropped them anyway) and delivers on.
"""

from __future__ import annotations

import mmap
from typing import Dict, List, Optional, Sequence, Set, Tuple

from minros.ros2.rtps import messages as m
from minros.ros2.rtps.endpoint import Address, Buffer, Datagram, Sample

__all__ = ["Reader", "WriterProxy"]

#: reassembly buffers this large or larger are anonymous memory maps (pages only when written)
_MMAP_FROM = 1 << 20


class _Reassembly:
    """One sample arriving in fragments."""

    __slots__ = ("size", "fragment_size", "total", "buffer", "view", "have", "missing",
                 "inline_qos", "timestamp", "little", "received", "updated", "nacked",
                 "interval", "highest", "announced", "last_nack")

    def __init__(self, size: int, fragment_size: int, timestamp: Optional[int],
                 buffer: mmap.mmap | bytearray | None = None) -> None:
        self.size = size
        self.fragment_size = fragment_size
        self.total = -(-size // fragment_size)
        if buffer is None:
            buffer = mmap.mmap(-1, size) if size >= _MMAP_FROM else bytearray(size)
        self.buffer: mmap.mmap | bytearray = buffer
        self.view = memoryview(self.buffer)
        self.have = bytearray(self.total)
        self.missing = self.total
        self.inline_qos: Optional[bytes] = None
        self.timestamp = timestamp
        self.little = True
        self.received = 0
        #: when a fragment last arrived, and when the reader last asked for the missing ones
        self.updated = 0.0
        self.nacked = -1.0
        self.interval = 0.0
        #: the newest fragment that came (1-based), and the last one a HEARTBEAT_FRAG named
        self.highest = 0
        self.announced = 0
        self.last_nack: List[int] = []

    def add(self, start: int, count: int, payload: memoryview) -> int:
        """Fragments ``start`` .. of ``payload``; returns the bytes that were new."""
        new = 0
        fsize = self.fragment_size
        for i in range(count):
            index = start - 1 + i
            if index >= self.total:
                break
            chunk = payload[i * fsize:(i + 1) * fsize]
            if not self.have[index] and chunk:
                offset = index * fsize
                want = min(fsize, self.size - offset)
                if len(chunk) < want:
                    break
                self.view[offset:offset + want] = chunk[:want]
                self.have[index] = 1
                self.missing -= 1
                new += want
                if index + 1 > self.highest:
                    self.highest = index + 1
        self.received += new
        return new

    def missing_fragments(self, limit: int = m.MAX_SET_BITS) -> Tuple[int, List[int]]:
        """(base, missing fragment numbers) for a NACK_FRAG: at most 256 from the first."""
        first = self.have.find(0)
        if first < 0:
            return 1, []
        base = first + 1
        out = [i + 1 for i in range(first, min(self.total, first + limit)) if not self.have[i]]
        return base, out


class WriterProxy:
    """The reader's view of one matched writer."""

    __slots__ = ("guid", "entity", "addresses", "next", "pending", "irrelevant", "partial",
                 "known", "synced", "hb_count", "acknack_count", "nackfrag_count", "prefix",
                 "last_delivered", "pending_bytes", "answer_due", "unsynced_since")

    def __init__(self, guid: bytes, addresses: Sequence[Address], message_header: bytes) -> None:
        self.guid = guid
        self.entity = guid[12:]
        self.addresses = list(addresses)
        #: every sequence number < next is delivered or irrelevant (reliable readers)
        self.next = 1
        self.pending: Dict[int, Sample] = {}
        self.pending_bytes = 0
        self.irrelevant: Set[int] = set()
        self.partial: Dict[int, _Reassembly] = {}
        #: the highest sequence number the writer said it has (HEARTBEAT)
        self.known = 0
        #: the first DATA or HEARTBEAT arrived: ``next`` is set
        self.synced = False
        self.hb_count = -(1 << 31)
        self.acknack_count = 0
        self.nackfrag_count = 0
        self.prefix = message_header + m.info_dst(guid[:12])
        #: best effort: the newest sequence number delivered
        self.last_delivered = 0
        #: when to answer the last HEARTBEAT (None: no answer owed)
        self.answer_due: Optional[float] = None
        #: when the first sample came while the writer had not said where to start
        self.unsynced_since: Optional[float] = None


class Reader:
    """One reader and its matched writers. Not thread-safe: its owner holds a lock."""

    def __init__(self, guid: bytes, message_header: bytes, *, reliable: bool = True,
                 durable: bool = False, max_sample_size: int = 256 << 20,
                 max_partial: int = 4, max_partial_bytes: int = 512 << 20,
                 max_pending: int = 10_000, max_pending_bytes: int = 256 << 20,
                 response_delay: float = 0.001, nack_delay: float = 0.03,
                 sync_timeout: float = 0.2) -> None:
        self.guid = guid
        self.entity = guid[12:]
        self.header = message_header
        self.reliable = reliable
        self.durable = durable
        self.max_sample_size = max_sample_size
        self.max_partial = max_partial
        self.max_partial_bytes = max_partial_bytes
        self.max_pending = max_pending
        self.max_pending_bytes = max_pending_bytes
        self.response_delay = response_delay
        self.nack_delay = nack_delay
        self.sync_timeout = sync_timeout
        #: samples :meth:`tick` released (a writer that never sent a HEARTBEAT): take them
        #: with :meth:`take_late`
        self.late: List[Sample] = []
        self._now = 0.0
        self.writers: Dict[bytes, WriterProxy] = {}
        self._partial_bytes = 0
        #: buffers of the last samples delivered, for :meth:`_reuse`
        self._delivered: List[mmap.mmap | bytearray] = []
        #: counters for tests: samples refused for their size, reassemblies dropped
        self.refused = 0
        self.dropped = 0

    # -- writers -----------------------------------------------------------------------------

    def add_writer(self, guid: bytes, addresses: Sequence[Address], now: float) -> List[Datagram]:
        """Match a writer; a reliable reader says it is there (a pre-emptive ACKNACK), so the
        writer answers with a HEARTBEAT without waiting for its period."""
        proxy = WriterProxy(guid, addresses, self.header)
        self.writers[guid] = proxy
        if not self.reliable:
            return []
        proxy.acknack_count += 1
        return [Datagram(proxy.addresses, [proxy.prefix, m.acknack(
            self.entity, proxy.entity, 1, (), proxy.acknack_count)])]

    def remove_writer(self, guid: bytes) -> None:
        proxy = self.writers.pop(guid, None)
        if proxy is not None:
            for r in proxy.partial.values():
                self._partial_bytes -= r.received

    def update_writer(self, guid: bytes, addresses: Sequence[Address]) -> None:
        proxy = self.writers.get(guid)
        if proxy is not None:
            proxy.addresses = list(addresses)

    def matched(self, guid: bytes) -> bool:
        return guid in self.writers

    # -- data --------------------------------------------------------------------------------

    def take_late(self) -> List[Sample]:
        out, self.late = self.late, []
        return out

    def on_data(self, sub: m.Data, now: float = 0.0) -> List[Sample]:
        """A DATA: the samples it makes deliverable, in order."""
        self._now = now
        proxy = self.writers.get(sub.src + sub.writer_id)
        if proxy is None or sub.payload is None:
            if proxy is not None and self.reliable:
                # a change without data (a dispose, a key only): it takes its number
                return self._arrived(proxy, sub.sn, None)
            return []
        self._sync(proxy, sub.sn)
        if self._stale(proxy, sub.sn):
            return []
        qos = bytes(sub.inline_qos) if sub.inline_qos is not None else None
        # the payload is a view of the receive buffer, which the next datagram overwrites
        sample = Sample(proxy.guid, sub.sn, bytes(sub.payload), sub.timestamp, qos,
                        bool(sub.flags & 0x01))
        return self._arrived(proxy, sub.sn, sample)

    def on_data_frag(self, sub: m.DataFrag, now: float = 0.0) -> List[Sample]:
        """A DATA_FRAG: the samples it completes and makes deliverable."""
        self._now = now
        proxy = self.writers.get(sub.src + sub.writer_id)
        if proxy is None:
            return []
        sn = sub.sn
        self._sync(proxy, sn)
        if self._stale(proxy, sn):
            return []
        r = proxy.partial.get(sn)
        if r is None:
            if sub.sample_size > self.max_sample_size:
                self.refused += 1
                return []
            while len(proxy.partial) >= self.max_partial:
                self._drop_partial(proxy, min(proxy.partial))
            r = _Reassembly(sub.sample_size, sub.fragment_size, sub.timestamp,
                            self._reuse(sub.sample_size))
            proxy.partial[sn] = r
        elif r.size != sub.sample_size or r.fragment_size != sub.fragment_size:
            return []  # the writer cannot change a sample's shape midway: ignore the fragment
        if sub.start == 1 and sub.inline_qos is not None:
            r.inline_qos = bytes(sub.inline_qos)
            r.little = bool(sub.flags & 0x01)
        new = r.add(sub.start, sub.count, sub.payload)
        r.updated = now
        self._partial_bytes += new
        while self._partial_bytes > self.max_partial_bytes:
            self._drop_oldest_partial()
            if sn not in proxy.partial:
                return []
        if r.missing:
            return []
        del proxy.partial[sn]
        self._partial_bytes -= r.received
        sample = Sample(proxy.guid, sn, r.view, r.timestamp, r.inline_qos, r.little)
        self._delivered.append(r.buffer)
        del self._delivered[:-2]
        return self._arrived(proxy, sn, sample)

    def _reuse(self, size: int) -> mmap.mmap | bytearray | None:
        """A memory map of a delivered sample nobody holds a view of any more, for the next
        sample of the same size: a fresh 6 MB buffer costs 1500 page faults, each zeroing a
        page. (A map with views exported refuses to be resized: that is the test.)"""
        delivered = self._delivered
        for i in range(len(delivered)):
            buffer = delivered[i]
            if isinstance(buffer, mmap.mmap) and len(buffer) == size:
                try:
                    buffer.resize(size)
                except (BufferError, OSError, ValueError, SystemError):
                    continue
                del delivered[i]
                return buffer
        return None

    def _drop_partial(self, proxy: WriterProxy, sn: int) -> None:
        r = proxy.partial.pop(sn)
        self._partial_bytes -= r.received
        self.dropped += 1

    def _drop_oldest_partial(self) -> None:
        oldest: Optional[Tuple[WriterProxy, int]] = None
        for proxy in self.writers.values():
            for sn in proxy.partial:
                if oldest is None or sn < oldest[1]:
                    oldest = (proxy, sn)
        if oldest is not None:
            self._drop_partial(*oldest)

    def _sync(self, proxy: WriterProxy, sn: int) -> None:
        """Samples before the writer's first HEARTBEAT (or GAP) wait: it says where this
        reader starts (a writer GAPs what a volatile reader is not meant to get, as Fast DDS
        and minros do), and data can arrive before this reader knew the writer."""
        if self.reliable and not proxy.synced and proxy.unsynced_since is None:
            proxy.unsynced_since = self._now

    def _stale(self, proxy: WriterProxy, sn: int) -> bool:
        if self.reliable:
            return sn in proxy.pending or (proxy.synced and (sn < proxy.next
                                                             or sn in proxy.irrelevant))
        return sn <= proxy.last_delivered

    def _arrived(self, proxy: WriterProxy, sn: int, sample: Optional[Sample]) -> List[Sample]:
        if not self.reliable:
            if sn <= proxy.last_delivered or sample is None:
                return []
            proxy.last_delivered = sn
            for old in [s for s in proxy.partial if s < sn]:
                self._drop_partial(proxy, old)
            return [sample]
        self._sync(proxy, sn)
        if sn in proxy.pending or (proxy.synced and (sn < proxy.next
                                                     or sn in proxy.irrelevant)):
            return []
        if sn > proxy.next or not proxy.synced:
            if sample is None:
                proxy.irrelevant.add(sn)
            else:
                proxy.pending[sn] = sample
                proxy.pending_bytes += len(sample.payload)
                # a writer that never fills the gap cannot make this grow without bound
                if len(proxy.pending) > self.max_pending or \
                        proxy.pending_bytes > self.max_pending_bytes:
                    return self._skip_to(proxy, min(proxy.pending))
            return []
        out: List[Sample] = [] if sample is None else [sample]
        proxy.next = sn + 1
        return out + self._drain(proxy)

    def _drain(self, proxy: WriterProxy) -> List[Sample]:
        out: List[Sample] = []
        while True:
            nxt = proxy.next
            sample = proxy.pending.pop(nxt, None)
            if sample is not None:
                proxy.pending_bytes -= len(sample.payload)
                out.append(sample)
            elif nxt in proxy.irrelevant:
                proxy.irrelevant.discard(nxt)
            else:
                break
            proxy.next = nxt + 1
        for sn in [s for s in proxy.partial if s < proxy.next]:
            self._drop_partial(proxy, sn)
        return out

    def _start_at(self, proxy: WriterProxy, sn: int) -> List[Sample]:
        """The writer said where this reader starts: what waited from there on is delivered."""
        proxy.synced = True
        proxy.unsynced_since = None
        for old in [s for s in proxy.pending if s < sn]:
            proxy.pending_bytes -= len(proxy.pending.pop(old).payload)
        proxy.next = sn
        return self._drain(proxy)

    def _skip_to(self, proxy: WriterProxy, sn: int) -> List[Sample]:
        proxy.irrelevant = {s for s in proxy.irrelevant if s > sn}
        proxy.next = sn
        return self._drain(proxy)

    def on_gap(self, sub: m.Gap) -> List[Sample]:
        """A GAP: the samples its skipped numbers were holding back."""
        proxy = self.writers.get(sub.src + sub.writer_id)
        if proxy is None or not self.reliable:
            return []
        if not proxy.synced:
            proxy.synced = True
            proxy.unsynced_since = None
            proxy.next = sub.start
        # a GAP's range may be huge (a peer's numbers): only the part at `next` is walked
        if sub.start <= proxy.next < sub.list_base:
            proxy.next = sub.list_base
        elif sub.start > proxy.next:
            span = min(sub.list_base, sub.start + self.max_pending)
            proxy.irrelevant.update(range(sub.start, span))
        proxy.irrelevant.update(s for s in sub.members if s >= proxy.next)
        for sn in [s for s in proxy.pending if s < proxy.next]:
            proxy.pending_bytes -= len(proxy.pending.pop(sn).payload)
        return self._drain(proxy)

    # -- heartbeats --------------------------------------------------------------------------

    def on_heartbeat(self, sub: m.Heartbeat,
                     now: float = 0.0) -> Tuple[List[Sample], List[Datagram]]:
        """A HEARTBEAT: the samples that a forward skip releases, and an answer to send now.

        Whole samples missing are asked for at once. Otherwise the answer waits
        ``response_delay`` (:meth:`tick` sends it): a writer that sends a HEARTBEAT after every
        fragment (Fast DDS does) gets one answer per burst, not one per fragment, and
        fragments still on their way are not asked for again."""
        proxy = self.writers.get(sub.src + sub.writer_id)
        if proxy is None or not self.reliable or sub.count <= proxy.hb_count:
            return [], []
        proxy.hb_count = sub.count
        delivered: List[Sample] = []
        if not proxy.synced:
            delivered = self._start_at(proxy, sub.first)
        if sub.last > proxy.known:
            proxy.known = sub.last
        if sub.first > proxy.next:
            # the writer no longer has what comes before `first`: those will never come
            delivered += self._skip_to(proxy, sub.first)
        missing = self._missing(proxy)
        if missing:
            return delivered, [self._answer(proxy, missing, now)]
        if not sub.final or proxy.partial:
            if proxy.answer_due is None:
                proxy.answer_due = now + self.response_delay
        return delivered, []

    def on_heartbeat_frag(self, sub: m.HeartbeatFrag, now: float = 0.0) -> List[Datagram]:
        """A HEARTBEAT_FRAG: fragments 1 .. ``last_fragment`` of a sample were sent. Answered
        at once (one datagram: NACK_FRAG of those missing, then ACKNACK), which is what a
        writer's flow control waits for."""
        proxy = self.writers.get(sub.src + sub.writer_id)
        if proxy is None or not self.reliable:
            return []
        r = proxy.partial.get(sub.sn)
        if r is not None and sub.last_fragment > r.announced:
            r.announced = min(sub.last_fragment, r.total)
        # the answer counts at least as high as the HEARTBEAT_FRAG it answers: a minros
        # writer knows by that which burst it answers (any count that grows is the spec's)
        proxy.acknack_count = max(proxy.acknack_count, sub.count - 1)
        return [self._answer(proxy, self._missing(proxy), now)]

    def _missing(self, proxy: WriterProxy) -> List[int]:
        top = min(proxy.known, proxy.next + m.MAX_SET_BITS - 1)
        have = proxy.pending
        skip = proxy.irrelevant
        return [sn for sn in range(proxy.next, top + 1)
                if sn not in have and sn not in skip and sn not in proxy.partial]

    def _answer(self, proxy: WriterProxy, missing: List[int], now: float) -> Datagram:
        """ACKNACK, after a NACK_FRAG for each half-received sample that misses fragments the
        writer has sent: those before the newest that came (a datagram's fragments leave in
        order), those a HEARTBEAT_FRAG named, and, when fragments stopped coming for
        ``nack_delay``, all. The same request is not repeated within a growing interval."""
        parts: List[Buffer] = [proxy.prefix]
        for sn in sorted(proxy.partial):
            r = proxy.partial[sn]
            stalled = now - r.updated >= self.nack_delay
            limit = r.total if stalled else max(r.highest - 1, r.announced)
            base, frags = r.missing_fragments()
            frags = [f for f in frags if f <= limit]
            if not frags:
                continue
            if frags == r.last_nack and now - r.nacked < r.interval:
                continue
            r.interval = self.nack_delay if frags != r.last_nack else min(r.interval * 2, 0.2)
            r.last_nack = frags
            r.nacked = now
            proxy.nackfrag_count += 1
            parts.append(m.nack_frag(self.entity, proxy.entity, sn, frags[0], frags,
                                     proxy.nackfrag_count))
        proxy.acknack_count += 1
        parts.append(m.acknack(self.entity, proxy.entity, proxy.next, missing,
                               proxy.acknack_count, final=not missing))
        proxy.answer_due = None
        return Datagram(proxy.addresses, parts)

    def tick(self, now: float) -> List[Datagram]:
        """Answers due: to HEARTBEATs (after ``response_delay``), and NACK_FRAGs for samples
        whose fragments stopped coming (the writer's HEARTBEAT may be seconds away: Fast
        DDS's period is 3 s)."""
        out: List[Datagram] = []
        if not self.reliable:
            return out
        for proxy in self.writers.values():
            if not proxy.synced and proxy.unsynced_since is not None \
                    and now - proxy.unsynced_since >= self.sync_timeout:
                # no HEARTBEAT came: start at the oldest sample that did
                first = min([*proxy.pending, *proxy.partial], default=proxy.next)
                self.late.extend(self._start_at(proxy, first))
            due = proxy.answer_due is not None and now >= proxy.answer_due
            stalled = any(self._stalled(r, now) for r in proxy.partial.values())
            if due or stalled:
                out.append(self._answer(proxy, self._missing(proxy), now))
        return out

    def _stalled(self, r: _Reassembly, now: float) -> bool:
        return now - r.updated >= self.nack_delay and now - r.nacked >= r.interval \
            and r.missing > 0

    def next_deadline(self) -> Optional[float]:
        """When :meth:`tick` has something to do (None: nothing pending)."""
        times = [max(r.updated + self.nack_delay, r.nacked + r.interval)
                 for p in self.writers.values() for r in p.partial.values()]
        times += [p.answer_due for p in self.writers.values() if p.answer_due is not None]
        times += [p.unsynced_since + self.sync_timeout for p in self.writers.values()
                  if not p.synced and p.unsynced_since is not None]
        return min(times) if times else None

    def nack_partial(self, writer: bytes) -> List[Datagram]:
        """NACK_FRAGs for the half-received samples of ``writer`` (its last fragment came and
        some did not: asking now repairs a burst's losses without waiting for a HEARTBEAT)."""
        proxy = self.writers.get(writer)
        if proxy is None or not self.reliable or not proxy.partial:
            return []
        now = max(r.updated for r in proxy.partial.values()) + self.nack_delay
        return [self._answer(proxy, self._missing(proxy), now)]
