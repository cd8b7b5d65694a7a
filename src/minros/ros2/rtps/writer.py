"""The RTPS writer as a state machine without I/O: its history, one proxy per matched reader,
reliability (HEARTBEAT, ACKNACK, GAP), fragmentation (DATA_FRAG, NACK_FRAG) and flow control.

A stateful writer keeps, for every matched reader, what that reader has acknowledged and what
it asked for again (:class:`ReaderProxy`)::

    write(payload)  -> the new sample to every proxy (DATA, or DATA_FRAGs burst by burst)
    ACKNACK         -> the reader has all before `base`, misses `missing`: resend or GAP them
    NACK_FRAG       -> the reader misses these fragments of one sample: resend them
    tick(now)       -> HEARTBEATs to readers that have not acknowledged everything yet

Reliable readers are sent a HEARTBEAT (first..last sequence number the writer still has for
them) after new data and periodically while data is unacknowledged; a reliable reader answers
a HEARTBEAT without the F flag with an ACKNACK (and NACK_FRAGs for half-received samples).

**Flow control.** A peer's UDP receive buffer is what the OS gives it (212992 bytes by default
on Linux: three 64 KiB datagrams; Fast DDS keeps that default), and a 6 MB image is a
hundred datagrams. Sent in one burst it overflows whenever the reader's thread is not
running at that moment, and on a loaded machine it often is not. So fragments go in
bursts of ``burst`` bytes, ``gap`` seconds apart (the code that calls :meth:`Writer.tick`
sends the next one), each followed by a HEARTBEAT and a HEARTBEAT_FRAG naming the last
fragment sent; the reader's answer (NACK_FRAG for what was lost, ACKNACK) is resent from,
and sizes the bursts: they halve after an answer naming losses and grow by a quarter after
a full burst without (AIMD, as TCP's window). A burst starts at what the reader's vendor is
known to receive (see the participant), and nothing waits for an answer unless
``max_unanswered`` bytes went without one: Fast DDS answers a HEARTBEAT only after 5 ms.

**History.** KEEP_LAST keeps the newest ``depth`` samples; KEEP_ALL keeps every sample until
each reliable reader has acknowledged it, at most ``max_samples`` (:meth:`Writer.full` says
when the caller should wait). A transient-local writer replays its history to every reader
that matches later and asks for it (durability TRANSIENT_LOCAL); a volatile one starts each
new reader at its next sample and GAPs what came before.
"""

from __future__ import annotations

from collections import OrderedDict, deque
from typing import Deque, Dict, List, Optional, Sequence, Set, Tuple

from minros.ros2.rtps import messages as m
from minros.ros2.rtps.endpoint import MAX_DATAGRAM, Address, Buffer, Datagram

__all__ = ["ReaderProxy", "Writer"]

#: sample payloads up to this size go in one DATA; larger ones in DATA_FRAGs of this size
FRAGMENT_SIZE = 64_000
#: overhead of header + INFO_DST + INFO_TS + DATA_FRAG header, without inline QoS
_FRAG_OVERHEAD = 20 + 16 + 12 + 36


class _Change:
    __slots__ = ("sn", "payload", "inline_qos", "timestamp", "key", "size")

    def __init__(self, sn: int, payload: Buffer, inline_qos: bytes, timestamp: Optional[int],
                 key: bool) -> None:
        self.sn = sn
        self.payload = payload
        self.inline_qos = inline_qos
        self.timestamp = timestamp
        self.key = key
        self.size = len(payload)


class ReaderProxy:
    """The writer's view of one matched reader."""

    __slots__ = ("guid", "entity", "addresses", "reliable", "durable", "start", "acked", "sent",
                 "resend", "frag_resend", "cursor", "unanswered", "burst", "next_send",
                 "paced", "acknack_count", "nackfrag_count", "hb_due", "hb_backoff",
                 "awaiting", "prefix", "lost", "rounds", "cuts", "announced", "bursts",
                 "answers_bursts", "cap", "answered")

    def __init__(self, guid: bytes, addresses: Sequence[Address], reliable: bool, durable: bool,
                 message_header: bytes, burst: int) -> None:
        self.guid = guid
        self.entity = guid[12:]
        self.addresses = list(addresses)
        self.reliable = reliable
        self.durable = durable
        #: the first sequence number this reader is meant to get
        self.start = 1
        #: every sequence number <= acked is acknowledged (or irrelevant to this reader)
        self.acked = 0
        #: the highest sequence number sent to this reader in order (new data goes after it)
        self.sent = 0
        #: asked for again (ACKNACK), whole samples
        self.resend: Set[int] = set()
        #: asked for again (NACK_FRAG), fragments of one sample
        self.frag_resend: Dict[int, Set[int]] = {}
        #: a sample sent in pieces: (sequence number, next fragment to send)
        self.cursor: Optional[Tuple[int, int]] = None
        #: bytes sent since the reader last answered
        self.unanswered = 0
        #: bytes of fragments sent in one go, then a pause of the writer's ``gap``
        self.burst = burst
        #: when the next burst may leave, and whether fragments wait for it
        self.next_send = 0.0
        self.paced = False
        self.acknack_count = -(1 << 31)
        self.nackfrag_count = -(1 << 31)
        #: when to send the next HEARTBEAT (None: nothing unacknowledged)
        self.hb_due: Optional[float] = None
        self.hb_backoff = 0.0
        #: ``max_unanswered`` bytes went without an answer: nothing more until one comes
        self.awaiting = False
        #: the message header and INFO_DST every datagram to this reader starts with
        self.prefix = message_header + m.info_dst(guid[:12])
        #: fragments resent since the last answer (this round's losses)
        self.lost = 0
        self.rounds = 0
        self.cuts = 0
        self.announced = 0
        #: a reader that answers every burst's HEARTBEAT_FRAG at once (minros's): what each
        #: unanswered burst held, oldest first, so an answer frees exactly its burst
        self.answers_bursts = False
        self.bursts: Deque[Tuple[int, int]] = deque()
        #: the highest ACKNACK count seen (such a reader's answer to a HEARTBEAT_FRAG counts
        #: at least as high as it: the bursts up to that one are answered)
        self.answered = -(1 << 31)
        #: bytes that may go without an answer
        self.cap = 64 << 20


class Writer:
    """One writer: its history and its readers. Not thread-safe: its owner holds a lock."""

    def __init__(self, guid: bytes, message_header: bytes, *, reliable: bool = True,
                 transient_local: bool = False, keep_all: bool = False, depth: int = 10,
                 max_samples: int = 5000, fragment_size: int = FRAGMENT_SIZE,
                 heartbeat_period: float = 0.1, burst: int = 3 * FRAGMENT_SIZE,
                 gap: float = 0.0003, max_burst: int = 8 << 20,
                 max_unanswered: int = 64 << 20) -> None:
        self.guid = guid
        self.entity = guid[12:]
        self.header = message_header
        self.reliable = reliable
        self.transient_local = transient_local
        self.keep_all = keep_all
        self.depth = max(1, depth)
        self.max_samples = max(1, max_samples)
        self.fragment_size = fragment_size
        self.heartbeat_period = heartbeat_period
        self.burst = burst
        self.gap = gap
        self.max_burst = max_burst
        self.max_unanswered = max_unanswered
        self.history: OrderedDict[int, _Change] = OrderedDict()
        self.last_sn = 0
        self.proxies: Dict[bytes, ReaderProxy] = {}
        self._hb_count = 0
        self._dirty: Set[bytes] = set()
        #: counters for tests and the benchmark: fragments sent again after a NACK_FRAG
        self.fragments_resent = 0
        self.samples_resent = 0

    # -- readers -----------------------------------------------------------------------------

    def add_reader(self, guid: bytes, addresses: Sequence[Address], reliable: bool,
                   durable: bool, now: float, burst: Optional[int] = None,
                   answers_bursts: bool = False, cap: Optional[int] = None) -> List[Datagram]:
        """Match a reader. A durable reader of a transient-local writer gets the history.
        ``burst``: the bytes of fragments it is sent in one go at first (what its receive
        buffer is thought to hold); ``answers_bursts``: it answers each HEARTBEAT_FRAG at
        once (then at most ``cap`` bytes go unanswered: a slow reader is waited for instead
        of overflowed)."""
        proxy = ReaderProxy(guid, addresses, reliable and self.reliable, durable,
                            self.header, burst or self.burst)
        proxy.answers_bursts = answers_bursts
        proxy.cap = cap or self.max_unanswered
        first = self._first_available()
        if durable and self.transient_local:
            proxy.start = first
            proxy.sent = proxy.acked = first - 1
        else:
            proxy.start = self.last_sn + 1
            proxy.sent = proxy.acked = self.last_sn
        self.proxies[guid] = proxy
        if proxy.reliable:
            # announce at once: the reader learns where it starts, and asks for the rest
            proxy.hb_due = now
        out = self._flush(proxy, now)
        return out + self._heartbeat_if_due(proxy, now)

    def remove_reader(self, guid: bytes) -> None:
        self.proxies.pop(guid, None)

    def update_reader(self, guid: bytes, addresses: Sequence[Address]) -> None:
        proxy = self.proxies.get(guid)
        if proxy is not None:
            proxy.addresses = list(addresses)

    def matched(self, guid: bytes) -> bool:
        return guid in self.proxies

    # -- writing -----------------------------------------------------------------------------

    def full(self) -> bool:
        """KEEP_ALL: the history holds ``max_samples`` unacknowledged samples (wait, or drop)."""
        return self.keep_all and len(self.history) >= self.max_samples and \
            self._oldest_unacked() <= next(iter(self.history))

    def write(self, payload: Buffer, now: float, *, inline_qos: bytes = b"",
              timestamp: Optional[int] = None, key: bool = False) -> Tuple[int, List[Datagram]]:
        """Add a sample (``payload`` with its encapsulation header; ``inline_qos`` a parameter
        list with its sentinel) and send it to every reader (a large one's first burst of
        allows. Returns its sequence number and the datagrams."""
        self.last_sn += 1
        sn = self.last_sn
        self.history[sn] = _Change(sn, payload, inline_qos, timestamp, key)
        self._trim_history()
        out: List[Datagram] = []
        for proxy in self.proxies.values():
            out += self._flush(proxy, now)
            if proxy.reliable:
                out += self._heartbeat_after_write(proxy, now)
        return sn, out

    def remove_change(self, sn: int) -> None:
        """Drop a change a newer one supersedes (a keyed built-in topic's old sample of an
        instance): readers that still ask for it get a GAP."""
        self.history.pop(sn, None)

    def _trim_history(self) -> None:
        history = self.history
        if not self.keep_all:
            while len(history) > self.depth:
                history.popitem(last=False)
            return
        # KEEP_ALL: drop what every reliable reader acknowledged, then the oldest beyond the
        # bound (the caller was told to wait by full() and chose to write anyway)
        oldest_unacked = self._oldest_unacked()
        while history and next(iter(history)) < oldest_unacked and len(history) > self.depth:
            history.popitem(last=False)
        while len(history) > self.max_samples:
            history.popitem(last=False)

    def _oldest_unacked(self) -> int:
        acked = [p.acked for p in self.proxies.values() if p.reliable]
        return min(acked) + 1 if acked else self.last_sn + 1

    def _first_available(self) -> int:
        return next(iter(self.history)) if self.history else self.last_sn + 1

    def acknowledged(self, sn: int) -> bool:
        """Whether every reliable reader acknowledged ``sn``."""
        return all(p.acked >= sn for p in self.proxies.values() if p.reliable)

    def unacknowledged(self) -> int:
        """Samples some reliable reader has not acknowledged yet."""
        return max(0, self.last_sn + 1 - self._oldest_unacked())

    # -- answers from readers ----------------------------------------------------------------

    def on_acknack(self, sub: m.AckNack, now: float) -> None:
        """An ACKNACK: what the reader has and misses. What to send in answer comes from
        :meth:`answer`, once every submessage of the datagram was given (a reader sends its
        NACK_FRAGs and ACKNACK together: one answer, not two)."""
        proxy = self.proxies.get(sub.src + sub.reader_id)
        if proxy is None or not proxy.reliable or sub.count <= proxy.acknack_count:
            return
        proxy.acknack_count = sub.count
        proxy.answered = max(proxy.answered, sub.count)
        base = sub.base
        if base - 1 > proxy.acked:
            proxy.acked = min(base - 1, self.last_sn)
        for sn in [s for s in proxy.frag_resend if s < base]:
            del proxy.frag_resend[sn]
        proxy.resend = {s for s in proxy.resend if s >= base}
        cursor = proxy.cursor
        if cursor is not None and cursor[0] < base:
            proxy.cursor = None
        for sn in sub.missing:
            if cursor is not None and sn == cursor[0]:
                # the reader has none of the sample in progress: its sent fragments again
                proxy.frag_resend.setdefault(sn, set()).update(range(1, cursor[1]))
            elif sn <= proxy.sent:
                proxy.resend.add(sn)
        self._answered(proxy, now)
        if proxy.acked >= self.last_sn:
            proxy.hb_due = None
        else:
            proxy.hb_due = now + self.heartbeat_period
            proxy.hb_backoff = self.heartbeat_period

    def on_nack_frag(self, sub: m.NackFrag, now: float) -> None:
        """A NACK_FRAG: fragments of one sample the reader misses (answered by :meth:`answer`)."""
        proxy = self.proxies.get(sub.src + sub.reader_id)
        if proxy is None or not proxy.reliable or sub.count <= proxy.nackfrag_count:
            return
        proxy.nackfrag_count = sub.count
        sn = sub.sn
        change = self.history.get(sn)
        if change is None or sn <= proxy.acked:
            return
        cursor = proxy.cursor
        limit = cursor[1] if cursor is not None and cursor[0] == sn else 1 << 31
        lost = {f for f in sub.missing if f < limit}
        if lost:
            proxy.frag_resend.setdefault(sn, set()).update(lost)
            proxy.lost += len(lost)
        self._answered(proxy, now)

    def answer(self, now: float) -> List[Datagram]:
        """What the ACKNACKs and NACK_FRAGs given since the last call ask to send."""
        out: List[Datagram] = []
        dirty, self._dirty = self._dirty, set()
        for guid in dirty:
            proxy = self.proxies.get(guid)
            if proxy is not None:
                self._settle(proxy, now)
                out += self._flush(proxy, now)
        return out

    def _answered(self, proxy: ReaderProxy, now: float) -> None:
        """The reader answered (what was in flight arrived, or is named lost): settled in
        :meth:`answer`, once the whole datagram was read."""
        self._dirty.add(proxy.guid)

    def _settle(self, proxy: ReaderProxy, now: float) -> None:
        """An answer came: after loss the bursts halve, after a clean one they grow by a
        fragment (between one fragment and ``max_burst``: AIMD)."""
        answered = 0
        if proxy.answers_bursts:
            while proxy.bursts and proxy.bursts[0][0] <= proxy.answered:
                answered += proxy.bursts.popleft()[1]
            proxy.unanswered = max(0, proxy.unanswered - answered)
        else:
            answered = proxy.unanswered
            proxy.unanswered = 0
            proxy.bursts.clear()
        if proxy.lost:
            proxy.burst = max(self.fragment_size, proxy.burst // 2)
            proxy.cuts += 1
        elif answered:
            proxy.burst = min(self.max_burst, proxy.burst + self.fragment_size)
        proxy.rounds += 1
        proxy.lost = 0
        if proxy.unanswered < proxy.cap:
            proxy.awaiting = False

    # -- time --------------------------------------------------------------------------------

    def tick(self, now: float) -> List[Datagram]:
        """The next bursts of fragments and the HEARTBEATs that are due."""
        out: List[Datagram] = []
        for proxy in self.proxies.values():
            if proxy.paced and now >= proxy.next_send and not proxy.awaiting:
                out += self._flush(proxy, now)
            if proxy.reliable:
                out += self._heartbeat_if_due(proxy, now)
        return out

    def next_deadline(self) -> Optional[float]:
        """When :meth:`tick` has something to do next (None: nothing pending)."""
        due = [p.hb_due for p in self.proxies.values() if p.hb_due is not None]
        due += [p.next_send for p in self.proxies.values() if p.paced and not p.awaiting]
        return min(due) if due else None

    def _heartbeat_if_due(self, proxy: ReaderProxy, now: float) -> List[Datagram]:
        if proxy.hb_due is None or now < proxy.hb_due:
            return []
        if proxy.acked >= self.last_sn and not proxy.awaiting and proxy.cursor is None \
                and not proxy.resend and not proxy.frag_resend and proxy.sent >= self.last_sn:
            # everything acknowledged: a new reader is still told where the writer stands
            # (twice, in case one is lost), then nothing until the next sample
            if proxy.announced >= 2:
                proxy.hb_due = None
                return []
            proxy.announced += 1
        backoff = proxy.hb_backoff or self.heartbeat_period
        proxy.hb_backoff = min(backoff * 2, 1.0)
        proxy.hb_due = now + backoff
        return [Datagram(proxy.addresses, [proxy.prefix, self._heartbeat(proxy, final=False)])]

    def _heartbeat_after_write(self, proxy: ReaderProxy, now: float) -> List[Datagram]:
        """A new sample went out: make sure a HEARTBEAT follows within the period."""
        if proxy.hb_due is None:
            proxy.hb_due = now + self.heartbeat_period
            proxy.hb_backoff = self.heartbeat_period
        return []

    def _heartbeat(self, proxy: ReaderProxy, final: bool) -> bytes:
        self._hb_count += 1
        first = max(self._first_available(), proxy.start)
        last = self.last_sn
        if first > last:
            first = last + 1
        return m.heartbeat(proxy.entity, self.entity, max(first, 1), last, self._hb_count,
                           final=final)

    # -- sending -----------------------------------------------------------------------------

    def _flush(self, proxy: ReaderProxy, now: float) -> List[Datagram]:
        """Everything this reader should get now: whole samples at once, fragments one burst
        at a time (the rest when :meth:`tick` says the next burst is due)."""
        batch = _Batch(proxy)
        history = self.history
        if proxy.resend:
            gaps: List[int] = []
            for sn in sorted(proxy.resend):
                change = history.get(sn)
                if change is None or sn < proxy.start:
                    gaps.append(sn)
                elif change.size > self.fragment_size:
                    proxy.frag_resend[sn] = set(range(1, self._fragments(change) + 1))
                else:
                    self._add_data(batch, proxy, change)
                    self.samples_resent += 1
            proxy.resend.clear()
            if gaps:
                self._add_gaps(batch, proxy, gaps)
        budget = proxy.burst if now >= proxy.next_send else 0
        if proxy.reliable and proxy.unanswered >= proxy.cap:
            budget = 0  # a reader that stopped answering is not flooded
            proxy.awaiting = True
        paced = False
        for sn in sorted(proxy.frag_resend):
            change = history.get(sn)
            frags = proxy.frag_resend[sn]
            if change is None:
                del proxy.frag_resend[sn]
                self._add_gaps(batch, proxy, [sn])
                continue
            for frag in sorted(frags):
                if budget <= 0:
                    paced = True
                    break
                budget -= self._add_fragment(batch, proxy, change, frag)
                frags.discard(frag)
                self.fragments_resent += 1
            if not frags:
                del proxy.frag_resend[sn]
            if paced:
                break
        if not paced and proxy.cursor is not None:
            paced, budget = self._continue_cursor(batch, proxy, budget)
        while not paced and proxy.sent < self.last_sn:
            sn = proxy.sent + 1
            change = history.get(sn)
            if change is None:  # dropped from the history before it was sent: a GAP
                proxy.sent = sn
                self._add_gaps(batch, proxy, [sn])
            elif change.size > self.fragment_size:
                if budget <= 0:
                    paced = True
                    break
                proxy.sent = sn
                proxy.cursor = (sn, 1)
                paced, budget = self._continue_cursor(batch, proxy, budget)
            else:
                proxy.sent = sn
                self._add_data(batch, proxy, change)
        proxy.paced = paced
        if batch.fragments:
            proxy.next_send = now + self.gap
            if proxy.reliable:
                # ask for an answer, naming the last fragment sent (a reader that reads
                # HEARTBEAT_FRAG, as minros and Cyclone do, answers at once with exactly the
                # ones lost; Fast DDS answers the HEARTBEAT, 5 ms later)
                parts: List[Buffer] = [self._heartbeat(proxy, final=False)]
                if batch.last_fragment is not None:
                    # counts leave room: a reader's other answers between two bursts, each
                    # counting one more, do not reach the next burst's
                    self._hb_count += 16
                    parts.append(m.heartbeat_frag(proxy.entity, self.entity,
                                                  *batch.last_fragment, self._hb_count))
                    proxy.bursts.append((self._hb_count, batch.fragment_bytes))
                batch.add(parts)
                proxy.hb_due = now + max(0.005, self.heartbeat_period / 4)
                proxy.hb_backoff = proxy.hb_due - now
        return batch.finish()

    def _continue_cursor(self, batch: _Batch, proxy: ReaderProxy,
                         budget: int) -> Tuple[bool, int]:
        """Fragments of the sample in progress while ``budget`` bytes last: (whether some wait
        for the next burst, the budget left)."""
        assert proxy.cursor is not None
        sn, frag = proxy.cursor
        change = self.history.get(sn)
        if change is None:
            proxy.cursor = None
            self._add_gaps(batch, proxy, [sn])
            return False, budget
        total = self._fragments(change)
        while frag <= total:
            if budget <= 0:
                proxy.cursor = (sn, frag)
                return True, budget
            budget -= self._add_fragment(batch, proxy, change, frag)
            frag += 1
        proxy.cursor = None
        return False, budget

    def _fragments(self, change: _Change) -> int:
        return -(-change.size // self.fragment_size)

    def _add_data(self, batch: _Batch, proxy: ReaderProxy, change: _Change) -> None:
        head, pad = m.data(proxy.entity, self.entity, change.sn, change.size, change.inline_qos,
                           change.key)
        parts: List[Buffer] = [head]
        if change.size:
            parts.append(change.payload)
        if pad:
            parts.append(pad)
        batch.add(parts, change.timestamp)
        proxy.unanswered += change.size

    def _add_fragment(self, batch: _Batch, proxy: ReaderProxy, change: _Change,
                      frag: int) -> int:
        size = self.fragment_size
        offset = (frag - 1) * size
        piece = memoryview(change.payload)[offset:offset + size]
        # the inline QoS goes with the first fragment only (the reader keeps it)
        qos = change.inline_qos if frag == 1 else b""
        head, pad = m.data_frag(proxy.entity, self.entity, change.sn, frag, 1, size, change.size,
                                len(piece), qos)
        parts: List[Buffer] = [head, piece]
        if pad:
            parts.append(pad)
        batch.add(parts, change.timestamp, alone=True)
        batch.fragments += 1
        batch.fragment_bytes += len(piece)
        batch.last_fragment = (change.sn, frag)
        proxy.unanswered += len(piece)
        return len(piece)

    def _add_gaps(self, batch: _Batch, proxy: ReaderProxy, sns: List[int]) -> None:
        for start, end in _runs(sns):
            batch.add([m.gap(proxy.entity, self.entity, start, end + 1)])


def _runs(sns: List[int]) -> List[Tuple[int, int]]:
    """Sorted numbers as (first, last) runs of consecutive ones."""
    out: List[Tuple[int, int]] = []
    for sn in sorted(set(sns)):
        if out and sn == out[-1][1] + 1:
            out[-1] = (out[-1][0], sn)
        else:
            out.append((sn, sn))
    return out


class _Batch:
    """Submessages to one reader, packed into datagrams of at most MAX_DATAGRAM bytes."""

    __slots__ = ("proxy", "parts", "size", "out", "timestamp", "fragments", "last_fragment",
                 "fragment_bytes")

    def __init__(self, proxy: ReaderProxy) -> None:
        self.proxy = proxy
        self.parts: List[Buffer] = [proxy.prefix]
        self.size = len(proxy.prefix)
        self.out: List[Datagram] = []
        self.timestamp: Optional[int] = -1
        self.fragments = 0
        self.fragment_bytes = 0
        #: (sequence number, fragment) of the last fragment added
        self.last_fragment: Optional[Tuple[int, int]] = None

    def add(self, parts: List[Buffer], timestamp: Optional[int] = -1,
            alone: bool = False) -> None:
        size = sum(len(p) for p in parts)
        stamp = b""
        if timestamp != -1 and timestamp != self.timestamp:
            stamp = m.info_ts(timestamp)
        if len(self.parts) > 1 and (alone or self.size + size + len(stamp) > MAX_DATAGRAM):
            self._close()
            if timestamp != -1:
                stamp = m.info_ts(timestamp)
        if stamp:
            self.parts.append(stamp)
            self.size += len(stamp)
            self.timestamp = timestamp
        self.parts.extend(parts)
        self.size += size
        if alone:
            self._close()

    def _close(self) -> None:
        if len(self.parts) > 1:
            self.out.append(Datagram(self.proxy.addresses, self.parts))
        self.parts = [self.proxy.prefix]
        self.size = len(self.proxy.prefix)
        self.timestamp = -1

    def finish(self) -> List[Datagram]:
        self._close()
        return self.out
