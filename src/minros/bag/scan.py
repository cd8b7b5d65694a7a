"""Reading a bag v2.0 front to back without its index, as ``rosbag reindex`` does, and writing
the index it rebuilds.

A bag may be cut short (a recorder that died, a full disk) or damaged anywhere (bit flips in
headers, chunks, index records). ROS's reindex stops at the first record that does not parse
and keeps what came before. This scan keeps more:

* a file header that does not parse is stepped over (the first record follows it at a known
  offset);
* a chunk that does not decompress, or whose records do not parse, costs that chunk only: the
  records of an uncompressed chunk up to the damage are kept, and the scan finds the next
  record by its header (``op=`` CHUNK or CONNECTION, checked field by field);
* connections are learned wherever their records are (in chunks, in the old index), and a
  message whose connection is nowhere to be found is dropped, not the chunk;
* the INDEX_DATA records after a chunk are checked against the chunk: where they are missing
  or wrong the chunk is rewritten after the last good one with new ones, so that every reader
  (ROS's too) finds an index that matches.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO, Callable, Dict, Iterator, List, Optional, Tuple, Union

from rosbags.interfaces import (
    Connection,
    ConnectionExtRosbag1,
    MessageDefinition,
    MessageDefinitionFormat,
)
from rosbags.rosbag1.reader import IndexData, decompressors, normalize
from rosbags.typesys.msg import normalize_msgtype

from minros.bag import records
from minros.bag.errors import Compression, ROSBagException
from minros.bag.records import (
    DATA_START,
    OP_CHUNK,
    OP_CONNECTION,
    OP_IDXDATA,
    OP_MSGDATA,
    ROSBAGS_DATA_START,
    Damage,
)

_U32 = records._U32


@dataclass
class ChunkSummary:
    """What ``rosbag info`` shows of a chunk: times, counts and sizes."""

    pos: int
    start: int  # ns, inclusive
    end: int  # ns, inclusive
    counts: Dict[int, int]
    compression: str = Compression.NONE
    compressed_size: int = 0
    uncompressed_size: int = 0


@dataclass
class ScannedChunk:
    """A chunk the scan read: where it is, what it holds, and whether the records after it
    index it."""

    pos: int
    compression: str
    size_field: int  # the uncompressed size its header states
    datapos: int
    datasize: int
    raw_size: int  # bytes after decompression
    good_size: int  # bytes of whole records (raw_size unless the chunk is damaged inside)
    entries: List[Tuple[int, int, int]]  # (connection, time ns, offset), in chunk order
    #: (connection, time ns, offset) of the INDEX_DATA records after it; None when damaged
    index: Optional[List[Tuple[int, int, int]]] = field(default_factory=list)
    index_records: int = 0
    group_end: int = 0  # end of those INDEX_DATA records

    @property
    def partial(self) -> bool:
        return self.good_size != self.raw_size


@dataclass
class ScanResult:
    """What a scan of the chunks found: enough to read the bag and to write its index."""

    connections: List[Connection] = field(default_factory=list)
    chunks: List[ChunkSummary] = field(default_factory=list)
    datapos: Dict[int, Tuple[int, int]] = field(default_factory=dict)  # chunk pos -> (datapos, datasize)
    indexes: Dict[int, List[IndexData]] = field(default_factory=lambda: defaultdict(list))
    #: end of the chunks (and their index records) that stay where they are
    good_end: int = DATA_START
    #: where the first record after the file header is
    data_start: int = DATA_START
    #: chunks to write again after ``good_end``, with an index that matches them
    relocate: List[ScannedChunk] = field(default_factory=list)
    #: the first damage met (a file cut short too), and the damage the scan found records after
    stopped: Optional[str] = None
    skipped: List[str] = field(default_factory=list)


def scan_chunks(path: Union[str, Path, BinaryIO],
                progress: Optional[Callable[[int], None]] = None) -> ScanResult:
    """Read every chunk of a bag from the front and rebuild its index."""
    result = ScanResult()
    for pos in iter_scan(path, result):
        if progress is not None:
            progress(pos)
    return result


def iter_scan(source: Union[str, Path, BinaryIO], result: ScanResult) -> Iterator[int]:
    """:func:`scan_chunks` as a generator of chunk offsets (for a progress bar); fills ``result``."""
    if isinstance(source, (str, Path)):
        with open(source, "rb") as f:
            yield from _scan(f, result)
    else:
        yield from _scan(source, result)


def check_version(f: BinaryIO) -> None:
    """Raise rosbag's ROSBagException unless ``f`` starts as a bag of format 2.x."""
    f.seek(0)
    try:
        version = records.read_version(f)
    except ValueError as exc:
        raise ROSBagException(str(exc)) from None
    if version // 100 != 2:
        raise ROSBagException(f"bag version {version} is not supported by minros (it reads 2.0)")


def _scan(f: BinaryIO, result: ScanResult) -> Iterator[int]:
    end = f.seek(0, os.SEEK_END)
    check_version(f)
    known: Dict[int, Connection] = {}
    chunks: List[ScannedChunk] = []
    start = records.data_start_of(f, end)
    if start is None:
        # ROS's and rosbags' file headers have known sizes; else the first record will do
        start = next((s for s in (DATA_START, ROSBAGS_DATA_START) if _plausible(f, s, end)), None)
        if start is None:
            start = _resync(f, len(records.MAGIC), end)
        _damaged(result, "the file header does not parse", start < end)
        if start >= end:
            start = DATA_START  # nothing to keep: the index goes where ROS's layout puts it
    result.data_start = start
    pos = start
    last: Optional[ScannedChunk] = None  # the chunk whose INDEX_DATA records may follow
    while pos < end:
        try:
            fields, datapos, dlen = records.read_record_header(f, pos, end, cut_data=True)
            op = records.u8(fields, "op")
            if datapos + dlen > end and op != OP_CHUNK:  # the records of a cut chunk are read
                raise Damage("a record's data runs past the end of the file")
        except Damage as exc:
            if last is not None:
                last.group_end, last = pos, None
            what = f"record at offset {pos}: {exc}"
            pos = _resync(f, pos + 1, end)
            _damaged(result, what, pos < end)
            continue
        if op == OP_IDXDATA and last is not None:
            _add_index_record(f, last, fields, datapos, dlen)
            pos = datapos + dlen
            continue
        if last is not None:
            last.group_end, last = pos, None
        if op == OP_CHUNK:
            yield pos
            chunk, problem = _read_chunk(f, pos, fields, datapos, dlen, known)
            if chunk is not None:
                chunks.append(chunk)
            if problem is None:
                assert chunk is not None
                last = chunk
                pos = datapos + dlen
                continue
            # a chunk that decompressed ends where it says; else what follows the damage is
            # unknown, and the next record is looked for from there
            if chunk is None:
                after = pos + 1
            elif chunk.compression == Compression.NONE:
                after = datapos + chunk.good_size
            else:
                after = datapos + dlen
            what = f"chunk at offset {pos}: {problem}"
            pos = _resync(f, max(after, pos + 1), end)
            _damaged(result, what, pos < end)
            continue
        if op == OP_CONNECTION:
            try:
                data = records.parse_fields(_read(f, datapos, dlen), 0, dlen)
                conn = parse_connection(fields, data)
            except Damage as exc:
                what = f"connection record at offset {pos}: {exc}"
                pos = _resync(f, pos + 1, end)
                _damaged(result, what, pos < end)
                continue
            known.setdefault(conn.id, conn)
        pos = datapos + dlen  # the old index's CHUNK_INFO records, or records minros does not know
    if last is not None:
        last.group_end = pos
    _finish(result, chunks, known)


def _damaged(result: ScanResult, what: str, more_follows: bool) -> None:
    """Note damage: ``more_follows`` when the scan found records after it (else the file
    just ends there, as a recording cut short does)."""
    if result.stopped is None:
        result.stopped = what
    if more_follows:
        result.skipped.append(what)


def _read(f: BinaryIO, pos: int, size: int) -> bytes:
    f.seek(pos)
    data = f.read(size)
    if len(data) != size:
        raise Damage("the file ends inside a record")
    return data


def parse_connection(fields: Dict[str, bytes], data: Dict[str, bytes]) -> Connection:
    """A rosbags Connection from a CONNECTION record's header and data fields."""
    latching = data.get("latching")
    try:
        latch = int(latching) if latching not in (None, b"") else None
    except ValueError:
        raise Damage("field 'latching' is not a number") from None
    return Connection(
        records.u32(fields, "conn"), normalize(records.text(fields, "topic") or "?"),
        rosbags_type(records.text(data, "type")),
        MessageDefinition(MessageDefinitionFormat.MSG,
                          records.text(data, "message_definition") if "message_definition" in data else ""),
        records.text(data, "md5sum"), 0,
        ConnectionExtRosbag1(records.text(data, "callerid") if "callerid" in data else None, latch),
        None)


def rosbags_type(datatype: str) -> str:
    """``std_msgs/String`` -> ``std_msgs/msg/String``; rosbags rejects the ROS 1 spelling."""
    return normalize_msgtype(datatype) if "/" in datatype else f"{datatype}/msg/{datatype}"


def _read_chunk(f: BinaryIO, pos: int, fields: Dict[str, bytes], datapos: int, dlen: int,
                known: Dict[int, Connection]) -> Tuple[Optional[ScannedChunk], Optional[str]]:
    """The chunk at ``pos`` and what is wrong with it (None when nothing is)."""
    end = f.seek(0, os.SEEK_END)
    try:
        compression = records.text(fields, "compression")
        size_field = records.u32(fields, "size")
        if datapos + dlen > end and compression != Compression.NONE:
            raise Damage("the file ends inside the chunk")
        data = _read(f, datapos, min(dlen, end - datapos))
    except Damage as exc:
        return None, str(exc)
    decompress = decompressors.get(compression)
    if decompress is None:
        return None, f"unsupported compression {compression!r}"
    try:
        raw = decompress(data)
    except Exception as exc:  # noqa: BLE001 - lz4, bz2 and zlib each raise their own kinds
        return None, f"{compression} data does not decompress ({type(exc).__name__}: {exc})"
    entries, good, problem = _chunk_records(raw, known)
    if len(data) < dlen:  # an uncompressed chunk cut short: the records before the cut count
        problem = problem or "the file ends inside the chunk"
    chunk = ScannedChunk(pos, compression, size_field, datapos, dlen, max(len(raw), dlen), good, entries)
    return chunk, problem


def _chunk_records(raw: bytes, known: Dict[int, Connection]
                   ) -> Tuple[List[Tuple[int, int, int]], int, Optional[str]]:
    """The messages of a decompressed chunk, learning its connections: (entries, bytes of
    whole records, what stopped the walk early)."""
    entries: List[Tuple[int, int, int]] = []
    offset, end = 0, len(raw)
    view = memoryview(raw)
    try:
        while offset < end:
            if offset + 4 > end:
                raise Damage("a record is cut short")
            (hlen,) = _U32.unpack_from(raw, offset)
            if offset + 8 + hlen > end:
                raise Damage("a record header overruns the chunk")
            fields = records.parse_fields(view, offset + 4, offset + 4 + hlen)
            op = records.u8(fields, "op")
            dpos = offset + 4 + hlen
            (dlen,) = _U32.unpack_from(raw, dpos)
            if dpos + 4 + dlen > end:
                raise Damage("a record's data overruns the chunk")
            if op == OP_MSGDATA:
                entries.append((records.u32(fields, "conn"), records.time_ns(fields, "time"), offset))
            elif op == OP_CONNECTION:
                conn = parse_connection(fields, records.parse_fields(view, dpos + 4, dpos + 4 + dlen))
                known.setdefault(conn.id, conn)
            else:
                raise Damage(f"a record of op {op} inside a chunk")
            offset = dpos + 4 + dlen
    except Damage as exc:
        return entries, offset, f"{exc} at offset {offset} of the chunk"
    return entries, offset, None


def _add_index_record(f: BinaryIO, chunk: ScannedChunk, fields: Dict[str, bytes], datapos: int,
                      dlen: int) -> None:
    chunk.index_records += 1
    if chunk.index is None:
        return
    try:
        cid, items = records.read_index_entries(fields, _read(f, datapos, dlen))
    except Damage:
        chunk.index = None
        return
    chunk.index.extend((cid, t, offset) for t, offset in items)


_CANDIDATE = re.compile(rb"\x04\x00\x00\x00op=[\x05\x07]")
_WINDOW = 1 << 20
#: how far before its op field a record header may start (fields written before ``op``:
#: rosbag_storage writes them in name order, e.g. ``compression`` or ``conn`` first)
_BEFORE_OP = 256


def _resync(f: BinaryIO, start: int, end: int) -> int:
    """The offset of the next plausible CHUNK or CONNECTION record at or after ``start``
    (``end`` when there is none)."""
    at = start
    while at < end:
        f.seek(at)
        window = f.read(_WINDOW + 8)
        for match in _CANDIDATE.finditer(window):
            field_at = at + match.start()
            if match.start() >= _WINDOW:
                break
            lo = max(start, field_at - 4 - _BEFORE_OP)
            for p in range(field_at - 4, lo - 1, -1):
                if _plausible(f, p, end, field_at):
                    return p
        at += _WINDOW
    return end


def _plausible(f: BinaryIO, pos: int, end: int, field_at: Optional[int] = None) -> bool:
    """Whether a CHUNK or CONNECTION record (whose op field is at ``field_at``) starts at ``pos``."""
    try:
        f.seek(pos)
        head = f.read(4)
        if len(head) < 4:
            return False
        (hlen,) = _U32.unpack(head)
        if field_at is not None and not pos + 4 <= field_at < pos + 4 + hlen:
            return False
        fields, datapos, dlen = records.read_record_header(f, pos, end)
        op = records.u8(fields, "op")
        if op == OP_CHUNK:
            records.u32(fields, "size")
            return records.text(fields, "compression") in decompressors
        if op == OP_CONNECTION:
            parse_connection(fields, records.parse_fields(_read(f, datapos, dlen), 0, dlen))
            return True
    except Damage:
        pass
    return False


def _finish(result: ScanResult, chunks: List[ScannedChunk], known: Dict[int, Connection]) -> None:
    """Keep the messages whose connection is known, and decide which chunks stay in place."""
    result.connections = sorted(known.values(), key=lambda c: c.id)
    staying_end = result.data_start
    for chunk in chunks:
        chunk.entries = [e for e in chunk.entries if e[0] in known]
        if not chunk.entries:
            continue
        counts: Dict[int, int] = {}
        for cid, _t, _o in chunk.entries:
            counts[cid] = counts.get(cid, 0) + 1
        times = [t for _c, t, _o in chunk.entries]
        datasize = chunk.good_size if chunk.partial and chunk.compression == Compression.NONE \
            else chunk.datasize
        result.chunks.append(ChunkSummary(chunk.pos, min(times), max(times), counts,
                                          chunk.compression, datasize, chunk.good_size))
        result.datapos[chunk.pos] = (chunk.datapos, datasize)
        for cid, t, offset in chunk.entries:
            result.indexes[cid].append(IndexData(t, chunk.pos, offset))
        indexed = (chunk.index is not None and chunk.index_records == len(counts)
                   and sorted(chunk.index) == sorted(chunk.entries))
        if indexed and not chunk.partial and chunk.size_field == chunk.raw_size:
            staying_end = max(staying_end, chunk.group_end)
        else:
            result.relocate.append(chunk)
    result.good_end = staying_end
    for cid in list(result.indexes):
        result.indexes[cid].sort()


# -- writing the index ------------------------------------------------------------------------

def rebuild(f: BinaryIO, scan: ScanResult) -> None:
    """Make the bag in ``f`` (open for update) whole from ``scan``: cut what follows the chunks
    that stay in place, write the others again after them with new INDEX_DATA records, then
    the index and the file header. (The offsets in ``scan`` stay those of before.)"""
    staying = {c.pos for c in scan.chunks} - {c.pos for c in scan.relocate}
    moved: Dict[int, int] = {}
    with tempfile.TemporaryFile() as spool:
        # read every chunk to move before anything is written: a new copy may land on an old one
        for chunk in scan.relocate:
            if chunk.partial:
                compression = Compression.NONE
                data = _good_records(f, chunk)
            else:
                compression, data = chunk.compression, _read(f, chunk.datapos, chunk.datasize)
            entries: Dict[int, List[Tuple[int, int]]] = defaultdict(list)
            for cid, t, offset in chunk.entries:
                entries[cid].append((t, offset))
            size = chunk.good_size if chunk.partial else chunk.raw_size
            moved[chunk.pos] = spool.tell()
            spool.write(records.chunk_header(compression, size, len(data)))
            spool.write(data)
            spool.write(records.index_data_records(entries))
        f.seek(scan.good_end)
        f.truncate()
        base = scan.good_end
        spool.seek(0)
        shutil.copyfileobj(spool, f)
    new_pos = {pos: base + off for pos, off in moved.items()}
    new_pos.update({pos: pos for pos in staying})
    by_pos = {c.pos: c for c in scan.chunks}
    index = []
    for old in sorted(new_pos, key=new_pos.get):
        c = by_pos[old]
        index.append((new_pos[old], c.start, c.end, c.counts))
    f.seek(0, os.SEEK_END)
    records.write_index(f, scan.connections, index, scan.data_start)
    f.flush()


def _good_records(f: BinaryIO, chunk: ScannedChunk) -> bytes:
    """The whole records at the front of a chunk damaged inside, uncompressed."""
    if chunk.compression == Compression.NONE:
        return _read(f, chunk.datapos, chunk.good_size)
    return decompressors[chunk.compression](_read(f, chunk.datapos, chunk.datasize))[:chunk.good_size]


def reindex_in_place(path: str, progress: Optional[Callable[[int], None]] = None) -> ScanResult:
    """``rosbag reindex``: scan the bag at ``path`` and rebuild its index in place."""
    with open(path, "r+b") as f:
        scan = ScanResult()
        for pos in iter_scan(f, scan):
            if progress is not None:
                progress(pos)
        rebuild(f, scan)
    return scan
