"""The RTPS writer and reader state machines driven against each other without sockets: a
simulated network that loses, duplicates and reorders datagrams (seeded), a simulated clock,
and a receive buffer that overflows the way a peer's UDP socket does."""

from __future__ import annotations

import random
from typing import List, Optional, Tuple

import pytest

from minros.ros2.rtps import messages as m
from minros.ros2.rtps.endpoint import Datagram, Sample
from minros.ros2.rtps.reader import Reader
from minros.ros2.rtps.writer import Writer

WPREFIX = bytes(range(1, 13))
RPREFIX = bytes(range(101, 113))
WGUID = WPREFIX + bytes.fromhex("00001003")
RGUID = RPREFIX + bytes.fromhex("00002004")


def payload(i: int, size: int = 20) -> bytes:
    return b"\x00\x01\x00\x00" + i.to_bytes(4, "little") + bytes([i % 251]) * (size - 8)


class Net:
    """One writer, one reader, the wire between them."""

    def __init__(self, *, loss: float = 0.0, dup: float = 0.0, reorder: float = 0.0,
                 seed: int = 1, buffer: Optional[int] = None, drain: int = 1 << 30,
                 reliable: bool = True, durable: bool = False, writer: Optional[Writer] = None,
                 reader: Optional[Reader] = None, **writer_args: object) -> None:
        self.rng = random.Random(seed)
        self.loss, self.dup, self.reorder = loss, dup, reorder
        self.now = 0.0
        self.writer = writer or Writer(WGUID, m.header(WPREFIX), **writer_args)  # type: ignore
        self.reader = reader or Reader(RGUID, m.header(RPREFIX), reliable=reliable,
                                       durable=durable)
        self.got: List[Sample] = []
        self.in_flight: List[Tuple[float, str, bytes]] = []
        #: the reader's socket: bytes queued, at most `buffer`, drained `drain` bytes per ms
        self.buffer, self.drain, self.queued = buffer, drain, 0
        self.drained_at = 0.0
        self.overflows = 0
        self.sent_to_reader = 0
        self.reader_matched = False

    def match(self, reliable: bool = True, durable: bool = False) -> None:
        self.send(self.writer.add_reader(RGUID, [("reader", 1)], reliable, durable, self.now))
        self.send(self.reader.add_writer(WGUID, [("writer", 1)], self.now))
        self.reader_matched = True

    def write(self, data: bytes) -> int:
        sn, out = self.writer.write(data, self.now, timestamp=int(self.now * 1e9))
        self.send(out)
        return sn

    def send(self, datagrams: List[Datagram]) -> None:
        # a burst leaves one datagram after the other (20 us per 64 KB, as sendmsg does here)
        at = self.now
        for dg in datagrams:
            to = dg.addresses[0][0]
            raw = dg.tobytes()
            at += 0.00002 * len(raw) / 65000
            copies = 0 if self.rng.random() < self.loss else 1
            if copies and self.rng.random() < self.dup:
                copies = 2
            for _ in range(copies):
                delay = 0.0002 + (self.rng.random() * 0.003 if self.rng.random() < self.reorder
                                  else 0.0)
                self.in_flight.append((at + delay, to, raw))

    def step(self, dt: float = 0.0001) -> None:
        self.now += dt
        due = sorted((x for x in self.in_flight if x[0] <= self.now), key=lambda x: x[0])
        self.in_flight = [x for x in self.in_flight if x[0] > self.now]
        for when, to, raw in due:
            if to == "reader" and self.buffer is not None:
                # the socket drains continuously; what does not fit is lost, as UDP's is
                self.queued = max(0, self.queued - int(self.drain * (when - self.drained_at)
                                                       * 1000))
                self.drained_at = when
                if self.queued + len(raw) > self.buffer:
                    self.overflows += 1
                    continue
                self.queued += len(raw)
            self.receive(to, raw)
        self.send(self.writer.tick(self.now))
        self.send(self.reader.tick(self.now))
        self.got += self.reader.take_late()

    def receive(self, to: str, raw: bytes) -> None:
        msg = m.parse_message(raw)
        assert msg.error is None
        if to == "reader":
            self.sent_to_reader += len(raw)
            for sub in msg.submessages:
                if isinstance(sub, m.Data):
                    self.got += self.reader.on_data(sub, self.now)
                elif isinstance(sub, m.DataFrag):
                    self.got += self.reader.on_data_frag(sub, self.now)
                    if sub.start + sub.count > sub.total:
                        self.send(self.reader.nack_partial(WGUID))
                elif isinstance(sub, m.Heartbeat):
                    samples, answer = self.reader.on_heartbeat(sub, self.now)
                    self.got += samples
                    self.send(answer)
                elif isinstance(sub, m.Gap):
                    self.got += self.reader.on_gap(sub)
                elif isinstance(sub, m.HeartbeatFrag):
                    self.send(self.reader.on_heartbeat_frag(sub, self.now))
        else:
            for sub in msg.submessages:
                if isinstance(sub, m.AckNack):
                    self.writer.on_acknack(sub, self.now)
                elif isinstance(sub, m.NackFrag):
                    self.writer.on_nack_frag(sub, self.now)
            self.send(self.writer.answer(self.now))

    def run_until(self, done, limit: float = 30.0) -> None:
        deadline = self.now + limit
        while not done():
            assert self.now < deadline, f"not done after {limit} s (simulated)"
            self.step()

    def numbers(self) -> List[int]:
        return [int.from_bytes(bytes(s.payload[4:8]), "little") for s in self.got]


@pytest.mark.parametrize("seed", range(5))
def test_reliable_delivery_in_order_exactly_once_despite_loss_duplicates_and_reordering(seed):
    net = Net(loss=0.3, dup=0.2, reorder=0.3, seed=seed, keep_all=True)
    net.match()
    for i in range(200):
        net.write(payload(i))
        net.step()
    net.run_until(lambda: len(net.got) >= 200 and net.writer.acknowledged(200))
    for _ in range(200):
        net.step()
    assert net.numbers() == list(range(200))
    assert [s.sn for s in net.got] == list(range(1, 201))
    assert net.writer.samples_resent > 0


@pytest.mark.parametrize("seed", range(3))
def test_fragmented_samples_arrive_whole_despite_loss(seed):
    net = Net(loss=0.1, dup=0.05, reorder=0.2, seed=seed, depth=10)
    net.match()
    sizes = [1_000_000, 200_001, 64_000, 64_001, 3_000_000]
    for i, size in enumerate(sizes):
        net.write(payload(i, size))
    net.run_until(lambda: len(net.got) == len(sizes))
    assert [len(s.payload) for s in net.got] == sizes
    assert [bytes(s.payload) for s in net.got] == [payload(i, size) for i, size in
                                                   enumerate(sizes)]
    assert net.writer.fragments_resent > 0


def test_flow_control_fits_a_small_receive_buffer():
    """6.2 MB images to a reader whose socket holds 212992 bytes (Linux's default) and drains
    1 GB/s while the writer sends at 3.2 GB/s: the bursts shrink to what fits, every image
    arrives whole, and later images need fewer fragments again than the first."""
    net = Net(buffer=212_992, drain=1_000_000, depth=2, burst=16 * 64_000)
    net.match()
    resent = []
    for i in range(4):
        before = net.writer.fragments_resent
        image = payload(i, 6_220_852)
        net.write(image)
        net.run_until(lambda i=i: len(net.got) == i + 1, limit=5)
        assert bytes(net.got[i].payload) == image
        resent.append(net.writer.fragments_resent - before)
    proxy = net.writer.proxies[RGUID]
    assert proxy.burst < 16 * 64_000 and proxy.cuts > 0
    assert sum(resent[1:]) / 3 < resent[0], resent
    assert net.now < 0.5  # four images in less than half a second of simulated time


def test_keep_last_drops_the_oldest_and_gaps_them():
    net = Net(loss=0.5, seed=3, depth=5)
    net.match()
    for i in range(50):
        net.write(payload(i))
    net.run_until(lambda: net.got and net.numbers()[-1] == 49)
    got = net.numbers()
    assert got == sorted(set(got)) and got[-1] == 49
    assert len(got) >= 5  # at least what the history still held


def test_transient_local_replays_its_history_to_a_late_durable_reader_only():
    net = Net(transient_local=True, depth=3)
    for i in range(5):
        net.write(payload(i))
    net.match(durable=True)
    net.run_until(lambda: len(net.got) == 3)
    assert net.numbers() == [2, 3, 4]
    # a volatile reader of the same writer gets what comes after it matched, not the history
    other = Reader(RPREFIX[:11] + b"\x99" + bytes.fromhex("00002004"), m.header(RPREFIX))
    net2 = Net(writer=net.writer, reader=other)
    net2.now = net.now
    net2.send(net.writer.add_reader(other.guid, [("reader", 1)], True, False, net.now))
    net2.send(other.add_writer(WGUID, [("writer", 1)], net.now))
    for _ in range(40):
        net2.step()
    assert net2.got == []
    net2.write(payload(5))
    net2.run_until(lambda: len(net2.got) == 1)
    assert net2.numbers() == [5]


def test_best_effort_delivers_newer_samples_only_and_never_asks():
    net = Net(loss=0.3, dup=0.3, reorder=0.5, seed=7, reliable=False)
    net.match(reliable=False)
    for i in range(100):
        net.write(payload(i))
        net.step()
    for _ in range(100):
        net.step()
    got = net.numbers()
    assert got == sorted(set(got)) and 30 < len(got) < 100
    assert net.writer.samples_resent == 0


def test_data_before_the_first_heartbeat_waits_for_it():
    """Samples can come before the reader knew the writer (its SEDP came later): they wait
    for the HEARTBEAT that says where the reader starts, then go out in order."""
    net = Net(depth=10)
    net.send(net.writer.add_reader(RGUID, [("reader", 1)], True, False, net.now))
    net.write(payload(0))
    net.write(payload(1))
    net.step()  # the first two reach a reader that does not know the writer: dropped
    net.send(net.reader.add_writer(WGUID, [("writer", 1)], net.now))
    net.write(payload(2))
    net.run_until(lambda: len(net.got) == 3)
    assert net.numbers() == [0, 1, 2]


# -- a writer that does not play fair -----------------------------------------------------------

def frag(sn: int, start: int, count: int, fsize: int, total: int, data: bytes = b"",
         src: bytes = WPREFIX) -> m.DataFrag:
    body = data or bytes(min(count * fsize, total - (start - 1) * fsize))
    head, pad = m.data_frag(RGUID[12:], WGUID[12:], sn, start, count, fsize, total, len(body))
    msg = m.parse_message(m.header(src) + head + body + pad)
    assert msg.error is None, msg.error
    return msg.submessages[0]  # type: ignore[return-value]


def test_a_sample_announced_too_large_is_refused_at_its_first_fragment():
    reader = Reader(RGUID, m.header(RPREFIX), max_sample_size=1 << 20)
    reader.add_writer(WGUID, [("w", 1)], 0.0)
    assert reader.on_data_frag(frag(1, 1, 1, 60_000, 2_000_000_000), 0.0) == []
    assert reader.refused == 1 and not reader.writers[WGUID].partial


def test_partial_samples_are_bounded_in_number_and_received_bytes():
    reader = Reader(RGUID, m.header(RPREFIX), max_partial=4, max_partial_bytes=300_000)
    reader.add_writer(WGUID, [("w", 1)], 0.0)
    for sn in range(1, 50):  # first fragments of 49 samples that never complete
        reader.on_data_frag(frag(sn, 1, 1, 60_000, 100_000_000), 0.0)
    proxy = reader.writers[WGUID]
    assert len(proxy.partial) <= 4
    assert reader._partial_bytes <= 300_000
    assert reader.dropped >= 45


def test_a_gap_that_never_fills_does_not_hold_samples_forever():
    reader = Reader(RGUID, m.header(RPREFIX), max_pending=100)
    reader.add_writer(WGUID, [("w", 1)], 0.0)
    hb = m.parse_message(m.header(WPREFIX) + m.heartbeat(RGUID[12:], WGUID[12:], 1, 0, 1))
    reader.on_heartbeat(hb.submessages[0], 0.0)  # type: ignore[arg-type]
    delivered = []
    for sn in range(2, 300):  # sample 1 never comes
        head, pad = m.data(RGUID[12:], WGUID[12:], sn, 8)
        msg = m.parse_message(m.header(WPREFIX) + head + payload(sn, 8) + pad)
        delivered += reader.on_data(msg.submessages[0], 0.0)  # type: ignore[arg-type]
        assert len(reader.writers[WGUID].pending) <= 101
    assert delivered and [s.sn for s in delivered] == sorted(s.sn for s in delivered)


def test_a_huge_gap_range_is_not_walked():
    reader = Reader(RGUID, m.header(RPREFIX))
    reader.add_writer(WGUID, [("w", 1)], 0.0)
    gap = m.parse_message(m.header(WPREFIX) + m.gap(RGUID[12:], WGUID[12:], 5, 1 << 40))
    reader.on_gap(gap.submessages[0])  # type: ignore[arg-type]
    assert len(reader.writers[WGUID].irrelevant) <= reader.max_pending


def test_keep_all_holds_what_is_unacknowledged_and_says_when_full():
    net = Net(keep_all=True, max_samples=5, depth=1)
    net.match()
    net.loss = 1.0  # nothing gets through: nothing is acknowledged
    for i in range(5):
        net.write(payload(i))
    assert net.writer.full() and len(net.writer.history) == 5
    net.loss = 0.0
    net.run_until(lambda: len(net.got) == 5 and not net.writer.full())
    assert net.numbers() == list(range(5))
    for _ in range(50):
        net.step()
    net.write(payload(5))
    assert len(net.writer.history) <= 2  # acknowledged samples left the history
