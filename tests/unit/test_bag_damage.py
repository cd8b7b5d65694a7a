"""Damaged bags: a reproducible corpus (seeded bit flips in the file header, chunk headers,
the records inside chunks, index records, truncations at many points) and what minros makes
of each file: ``rosbag info``, ``check`` and ``reindex`` print at most one line (no traceback),
reading raises only the ROSBagException family, and ``reindex`` keeps every message outside
the damaged chunk. tests/interop/test_bag_damage_interop.py holds the same corpus against
Debian's rosbag.

The corpus is built from bags minros writes (no reference needed); ``damaged_corpus`` is the
generator both tests use.
"""

from __future__ import annotations

import contextlib
import io
import random
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Optional, Tuple

import pytest

import minros
from minros.bag import Bag, ROSBagException
from std_msgs.msg import Int32, String

SEED = 23
MAGIC_LEN = 13  # b"#ROSBAG V2.0\n"
OP_MSGDATA, OP_FILE_HEADER, OP_IDXDATA, OP_CHUNK, OP_CHUNK_INFO, OP_CONNECTION = 2, 3, 4, 5, 6, 7


@dataclass
class Record:
    """One record of a bag v2.0 file: where its parts are, and its op."""

    start: int
    data_start: int  # after the data length field
    end: int
    op: int
    fields: Dict[bytes, bytes]


def walk(raw: bytes, pos: int, end: int) -> List[Record]:
    """The records of an undamaged ``raw[pos:end]``, with nothing but struct (a second opinion
    on the layout, independent of minros's reader)."""
    out = []
    while pos < end:
        (hlen,) = struct.unpack_from("<I", raw, pos)
        fields, at = {}, pos + 4
        while at < pos + 4 + hlen:
            (flen,) = struct.unpack_from("<I", raw, at)
            name, _, value = raw[at + 4:at + 4 + flen].partition(b"=")
            fields[name] = value
            at += 4 + flen
        (dlen,) = struct.unpack_from("<I", raw, at)
        out.append(Record(pos, at + 4, at + 4 + dlen, fields[b"op"][0], fields))
        pos = at + 4 + dlen
    return out


@dataclass
class Chunk:
    record: Record
    group_end: int  # end of the INDEX_DATA records after it
    messages: int


@dataclass
class Base:
    """An undamaged bag of the corpus and its layout."""

    path: Path
    compression: str
    raw: bytes
    records: List[Record]
    chunks: List[Chunk]
    messages: int

    def chunk_at(self, offset: int) -> Optional[Chunk]:
        """The chunk whose record or index records hold ``offset``."""
        return next((c for c in self.chunks if c.record.start <= offset < c.group_end), None)

    def whole_before(self, offset: int) -> int:
        """Messages of the chunks whose record ends before ``offset``."""
        return sum(c.messages for c in self.chunks if c.record.end <= offset)


def make_base(directory: Path, compression: str) -> Base:
    path = directory / f"base-{compression}.bag"
    with Bag(str(path), "w", compression=compression, chunk_threshold=1500) as b:
        for i in range(120):
            t = minros.Time(1000 + i // 10, (i % 10) * 100_000_000)
            b.write("/words", String(f"w{i:03d} " + "x" * (i % 40)), t)
            if i % 2 == 0:
                b.write("/count", Int32(i), t)
    raw = path.read_bytes()
    (hlen,) = struct.unpack_from("<I", raw, MAGIC_LEN)
    (plen,) = struct.unpack_from("<I", raw, MAGIC_LEN + 4 + hlen)
    records = walk(raw, MAGIC_LEN + 8 + hlen + plen, len(raw))
    chunks = []
    for i, rec in enumerate(records):
        if rec.op == OP_CHUNK:
            group_end = rec.end
            for nxt in records[i + 1:]:
                if nxt.op != OP_IDXDATA:
                    break
                group_end = nxt.end
            count = sum(struct.unpack("<I", r.fields[b"count"])[0] for r in records[i + 1:]
                        if r.op == OP_IDXDATA and r.start < group_end)
            chunks.append(Chunk(rec, group_end, count))
    return Base(path, compression, raw, records, chunks, 180)


@dataclass
class Damaged:
    """One file of the corpus."""

    name: str
    path: Path
    kind: str  # "flip" or "cut"
    region: str
    offset: int
    #: messages any reindex worth the name keeps: all but those of the damaged chunk (a bit
    #: flip), or those of the chunks before the cut (a truncation)
    keepable: int


def _regions(base: Base) -> Dict[str, List[Tuple[int, int]]]:
    """Byte ranges of each kind of structure in ``base``."""
    raw = base.raw
    (hlen,) = struct.unpack_from("<I", raw, MAGIC_LEN)
    regions: Dict[str, List[Tuple[int, int]]] = {
        "file-header": [(MAGIC_LEN, MAGIC_LEN + 8 + hlen)], "chunk-header": [],
        "record-header": [], "message-data": [], "chunk-data": [], "index-data": [],
        "connection": [], "chunk-info": []}
    for rec in base.records:
        if rec.op == OP_CHUNK:
            regions["chunk-header"].append((rec.start, rec.data_start))
            regions["chunk-data"].append((rec.data_start, rec.end))
            if base.compression == "none":
                for inner in walk(raw, rec.data_start, rec.end):
                    if inner.op == OP_CONNECTION:
                        regions["record-header"].append((inner.start, inner.end))
                    else:
                        regions["record-header"].append((inner.start, inner.data_start))
                        regions["message-data"].append((inner.data_start, inner.end))
        elif rec.op == OP_IDXDATA:
            regions["index-data"].append((rec.start, rec.end))
        elif rec.op == OP_CONNECTION:
            regions["connection"].append((rec.start, rec.end))
        elif rec.op == OP_CHUNK_INFO:
            regions["chunk-info"].append((rec.start, rec.end))
    return regions


#: bit flips per region, for each base compression
FLIPS = {
    "none": {"file-header": 4, "chunk-header": 10, "record-header": 12, "message-data": 3,
             "index-data": 8, "connection": 5, "chunk-info": 5},
    "lz4": {"chunk-header": 2, "chunk-data": 5},
    "bz2": {"chunk-data": 4},
}
#: truncation points per base compression, spread evenly over the file
CUTS = {"none": 20, "lz4": 3, "bz2": 2}


def damaged_corpus(directory: Path, seed: int = SEED) -> List[Damaged]:
    """The damaged files, written into ``directory`` (86 of them; the same for the same seed)."""
    rng = random.Random(seed)
    out: List[Damaged] = []
    for compression in ("none", "lz4", "bz2"):
        base = make_base(directory, compression)
        regions = _regions(base)
        for region, n in FLIPS[compression].items():
            for i in range(n):
                lo, hi = rng.choice(regions[region])
                offset = rng.randrange(lo, hi)
                data = bytearray(base.raw)
                data[offset] ^= 1 << rng.randrange(8)
                chunk = base.chunk_at(offset)
                keepable = base.messages - (chunk.messages if chunk else 0)
                name = f"{compression}-flip-{region}-{i}"
                out.append(Damaged(name, directory / f"{name}.bag", "flip", region, offset, keepable))
                out[-1].path.write_bytes(bytes(data))
        size = len(base.raw)
        points = [size * (k + 1) // (CUTS[compression] + 1) for k in range(CUTS[compression])]
        if compression == "none":
            middle = base.chunks[len(base.chunks) // 2]
            points += [middle.record.end, middle.group_end - 3, size - 1]
        for i, cut in enumerate(points):
            chunk = base.chunk_at(cut)
            name = f"{compression}-cut-{i}"
            out.append(Damaged(name, directory / f"{name}.bag", "cut",
                               chunk and "chunk" or "index", cut, base.whole_before(cut)))
            out[-1].path.write_bytes(base.raw[:cut])
    return out


# ---------------------------------------------------------------------------------------------
# what minros does with each file


ROS_FAMILY = ROSBagException


def run_cli(*argv: str) -> Tuple[int, str, str]:
    """``rosbag ARGV`` in this process: (status, stdout, stderr); an exception fails the test."""
    from minros.cli.bag import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(list(argv))
    return status, out.getvalue(), err.getvalue()


def read_all(path: Path, allow_unindexed: bool = False, raw: bool = False) -> Tuple[int, Optional[Exception]]:
    """(messages read, the exception that ended reading or None)."""
    n = 0
    try:
        with Bag(str(path), allow_unindexed=allow_unindexed) as b:
            for _ in b.read_messages(raw=raw):
                n += 1
    except Exception as exc:  # noqa: BLE001 - the test classifies every exception
        return n, exc
    return n, None


def recovered(path: Path, outdir: Path) -> Tuple[int, str]:
    """``rosbag reindex --output-dir`` of ``path``: (messages the result holds, its stderr)."""
    status, _out, err = run_cli("reindex", "-q", "--output-dir", str(outdir), str(path))
    assert status == 0
    result = outdir / path.name
    if not result.exists():
        return 0, err
    n, exc = read_all(result, raw=True)
    assert exc is None, f"{path.name}: the reindexed bag does not read: {exc!r}"
    return n, err


def one_line(text: str, what: str) -> None:
    lines = text.strip().splitlines()
    assert len(lines) <= 1, f"{what}: {text}"
    assert "Traceback" not in text, f"{what}: {text}"


@pytest.fixture(scope="module")
def corpus(tmp_path_factory) -> List[Damaged]:
    return damaged_corpus(tmp_path_factory.mktemp("damaged"))


def test_corpus_is_reproducible(tmp_path, corpus):
    again = damaged_corpus(tmp_path)
    assert len(again) == len(corpus) == 86
    assert [(d.name, d.offset) for d in again] == [(d.name, d.offset) for d in corpus]
    assert all(a.path.read_bytes() == d.path.read_bytes() for a, d in zip(again, corpus))


@pytest.mark.slow  # over half a CPU-second of its own
def test_info_and_check_print_one_line(corpus):
    for d in corpus:
        for cmd in ("info", "check"):
            status, out, err = run_cli(cmd, str(d.path))
            one_line(err, f"rosbag {cmd} {d.name}")
            if status:
                assert err.startswith("ERROR "), (cmd, d.name, err)
            if err.startswith("ERROR bag unindexed"):
                assert err.strip() == f"ERROR bag unindexed: {d.path}.  Run rosbag reindex."


def test_reading_raises_only_rosbag_exceptions(corpus):
    for d in corpus:
        for allow_unindexed in (False, True):
            _n, exc = read_all(d.path, allow_unindexed)
            if exc is not None:
                assert isinstance(exc, ROS_FAMILY), f"{d.name}: {exc!r}"
                one_line(str(exc), d.name)


def test_reindex_keeps_all_but_the_damaged_chunk(corpus, tmp_path):
    short = []
    for d in corpus:
        outdir = tmp_path / d.name
        outdir.mkdir()
        n, err = recovered(d.path, outdir)
        one_line(err, f"rosbag reindex {d.name}")
        if n < d.keepable:
            short.append((d.name, n, d.keepable))
    assert not short, short


def test_damaged_mcap_files_raise_only_rosbag_exceptions(tmp_path):
    """The same for MCAP files (read through the mcap library): 90 seeded flips and cuts."""
    path = tmp_path / "base.mcap"
    with Bag(str(path), "w", chunk_threshold=1000) as b:
        for i in range(200):
            b.write("/s", String(f"m{i:03d}"), minros.Time(1 + i))
    raw = path.read_bytes()
    rng = random.Random(SEED)
    damaged = tmp_path / "damaged.mcap"
    for k in range(90):
        data = bytearray(raw)
        if k % 3 == 0:
            data = data[:rng.randrange(len(data))]
        else:
            data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        damaged.write_bytes(bytes(data))
        for allow_unindexed in (False, True):
            _n, exc = read_all(damaged, allow_unindexed)
            if exc is not None:
                assert isinstance(exc, ROS_FAMILY), f"case {k}: {exc!r}"
                one_line(str(exc), f"case {k}")
