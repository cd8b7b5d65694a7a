"""Bag format 2.0 through the ``rosbags`` library: reading, writing, appending, reindexing.

rosbags (Ternaris) reads and writes the records; minros adds only what it lacks:

* **summary-only open**: rosbags' ``Reader.open`` loads every index entry, which ``rosbag info``
  does not need (a bag of millions of small messages has millions of entries). The reader below
  skips the INDEX_DATA records on open and loads them on the first read.
* **reindexing** a bag whose index was never written (a ``.bag.active`` left by a recorder that
  died): the chunks are scanned with rosbags' record parser and the index is rebuilt.
* **appending** and **reindexing in place**: rosbags' ``Writer`` only creates new files, so it is
  handed the existing file, positioned after its last good chunk, with the connections and chunk
  list that file already has; its ``close`` then writes the index as for a new bag.
"""

from __future__ import annotations

import bisect
import itertools
import operator
import os
import struct
from collections import defaultdict
from dataclasses import dataclass, field
from io import BytesIO
from pathlib import Path
from typing import Any, Callable, Dict, Iterator, List, Optional, Tuple

from rosbags.interfaces import (
    Connection,
    ConnectionExtRosbag1,
    MessageDefinition,
    MessageDefinitionFormat,
)
from rosbags.rosbag1 import reader as _rb_reader
from rosbags.rosbag1 import writer as _rb_writer
from rosbags.rosbag1.reader import Chunk, ChunkInfo, Header, IndexData, ReaderError, RecordType
from rosbags.typesys.msg import denormalize_msgtype, normalize_msgtype

from minros.bag.errors import (
    Compression,
    ROSBagException,
    ROSBagFormatException,
    ROSBagUnindexedException,
)

MAGIC = b"#ROSBAG V2.0\n"
_U32 = struct.Struct("<I")
_by_time = operator.itemgetter(0)
_chunk_pos = operator.itemgetter(1)
_offset = operator.itemgetter(2)
#: the file header record is padded to this many bytes (after the magic line)
FILE_HEADER_LENGTH = 4096
#: where the first record after the file header starts
DATA_START = len(MAGIC) + FILE_HEADER_LENGTH


@dataclass
class ConnInfo:
    """One connection of a bag: a topic with the header of the publisher it was recorded from."""

    id: int
    topic: str
    datatype: str
    md5sum: str
    msg_def: str
    callerid: Optional[str] = None
    latching: Optional[str] = None

    @property
    def header(self) -> Dict[str, bytes]:
        """The connection header as rosbag returns it (values are bytes)."""
        out = {"topic": self.topic, "type": self.datatype, "md5sum": self.md5sum,
               "message_definition": self.msg_def}
        if self.callerid is not None:
            out["callerid"] = self.callerid
        if self.latching is not None:
            out["latching"] = self.latching
        return {k: v.encode() for k, v in out.items()}


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


def chunks_time_range(chunks: List[ChunkSummary]) -> Optional[Tuple[int, int]]:
    """(first, last) receive time in ns of the messages in ``chunks``; None if they have none."""
    full = [c for c in chunks if c.counts]
    if not full:
        return None
    return min(c.start for c in full), max(c.end for c in full)


def ros1_type(msgtype: str) -> str:
    """``std_msgs/msg/String`` (rosbags' spelling) -> ``std_msgs/String``."""
    return denormalize_msgtype(msgtype) if "/msg/" in msgtype else msgtype


def rosbags_type(datatype: str) -> str:
    """``std_msgs/String`` -> ``std_msgs/msg/String``; rosbags rejects the ROS 1 spelling."""
    return normalize_msgtype(datatype) if "/" in datatype else f"{datatype}/msg/{datatype}"


def _conn_info(conn: Connection) -> ConnInfo:
    ext = conn.ext
    latching = None
    if isinstance(ext, ConnectionExtRosbag1) and ext.latching is not None:
        latching = str(ext.latching)
    return ConnInfo(conn.id, conn.topic, ros1_type(conn.msgtype), conn.digest, conn.msgdef.data,
                    ext.callerid if isinstance(ext, ConnectionExtRosbag1) else None, latching)


def _reader_error(exc: Exception) -> ROSBagException:
    text = str(exc.args[0]) if exc.args else str(exc)
    if text == "File magic is invalid.":
        return ROSBagException("This does not appear to be a bag file")
    if "seems to be empty" in text:
        return ROSBagException("empty file")
    if text.startswith("Bag version"):
        return ROSBagException(text)
    if "encryption" in text:
        return ROSBagException(text + " by minros")
    # as rosbag: an index that is missing, cut short or damaged means "run rosbag reindex"
    return ROSBagUnindexedException()


class _Reader(_rb_reader.Reader):
    """rosbags' reader that keeps each chunk's compression and sizes, and skips INDEX_DATA
    records on open (``load_index`` reads them when messages are first needed)."""

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        self.chunk_meta: Dict[int, Tuple[str, int, int]] = {}
        self.index_loaded = False

    def read_chunk(self) -> Chunk:
        assert self.bio
        pos = self.bio.tell()
        header = Header.read(self.bio, RecordType.CHUNK)
        compression = header.get_string("compression")
        size = header.get_uint32("size")
        datasize = _rb_reader.read_uint32(self.bio)
        datapos = self.bio.tell()
        self.bio.seek(datasize, os.SEEK_CUR)
        try:
            decompressor = _rb_reader.decompressors[compression]
        except KeyError:
            raise ReaderError(f"Compression {compression!r} is not supported.") from None
        self.chunk_meta[pos] = (compression, size, datasize)
        return Chunk(datasize, datapos, decompressor)

    def read_index_data(self, pos: int, indexes: Dict[int, List[IndexData]]) -> None:
        if self.index_loaded:
            # rosbags learns the field order of INDEX_DATA headers from the first one; a bag
            # appended to by another writer mixes orders, so learn it again for each record
            self.index_data_header_offsets = None
            super().read_index_data(pos, indexes)
        # else: the next chunk is found through its CHUNK_INFO record, nothing to skip here

    def load_index(self) -> None:
        if self.index_loaded:
            return
        assert self.bio
        self.index_loaded = True
        indexes: Dict[int, List[IndexData]] = defaultdict(list)
        for info in self.chunk_infos:
            self.bio.seek(info.pos)
            Header.read(self.bio, RecordType.CHUNK)
            self.bio.seek(_rb_reader.read_uint32(self.bio), os.SEEK_CUR)
            for _ in range(len(info.connection_counts)):
                self.read_index_data(info.pos, indexes)
        self.indexes = {c.id: sorted(indexes[c.id]) for c in self.connections}


@dataclass
class ScanResult:
    """What a scan of the chunks found: enough to read the bag and to write its index."""

    connections: List[Connection] = field(default_factory=list)
    chunks: List[ChunkSummary] = field(default_factory=list)
    datapos: Dict[int, Tuple[int, int]] = field(default_factory=dict)  # chunk pos -> (datapos, datasize)
    indexes: Dict[int, List[IndexData]] = field(default_factory=lambda: defaultdict(list))
    #: end of the last chunk (and its index records) that was read whole
    good_end: int = DATA_START
    #: why the scan stopped before the end of the file, if it did
    stopped: Optional[str] = None


def scan_chunks(path: Path, progress: Optional[Callable[[int], None]] = None) -> ScanResult:
    """Read every chunk of a bag from the front, as ``rosbag reindex`` does, and rebuild its
    index. Stops at the first record that is cut short or damaged; what came before is kept."""
    result = ScanResult()
    for pos in iter_scan(path, result):
        if progress is not None:
            progress(pos)
    return result


def iter_scan(path: Path, result: ScanResult) -> Iterator[int]:
    """:func:`scan_chunks` as a generator of record offsets (for a progress bar); fills ``result``."""
    known: Dict[int, Connection] = {}
    with open(path, "rb") as f:
        f.seek(0, os.SEEK_END)
        total = f.tell()
        f.seek(0)
        if f.readline() != MAGIC:
            raise ROSBagException("This does not appear to be a bag file")
        try:
            Header.read(f, RecordType.BAGHEADER)
            f.seek(_rb_reader.read_uint32(f), os.SEEK_CUR)
        except ReaderError as exc:
            raise ROSBagFormatException(f"damaged file header: {exc}") from None
        result.good_end = f.tell()
        while f.tell() < total:
            pos = f.tell()
            yield pos
            try:
                header = Header.read(f)
                op = header.get_uint8("op")
                size = _rb_reader.read_uint32(f)
                if op == RecordType.CHUNK:
                    data = _rb_reader.read_bytes(f, size)
                    compression = header.get_string("compression")
                    if compression not in _rb_reader.decompressors:
                        raise ReaderError(f"unsupported compression {compression!r}")
                    raw = _rb_reader.decompressors[compression](data)
                    chunk, entries = _scan_chunk(raw, pos, known)
                    chunk.compression = compression
                    chunk.compressed_size = size
                    chunk.uncompressed_size = len(raw)
                    for cid, items in entries.items():
                        result.indexes[cid].extend(items)
                    if chunk.counts:
                        result.chunks.append(chunk)
                        result.datapos[pos] = (f.tell() - size, size)
                    result.good_end = f.tell()
                elif op == RecordType.IDXDATA:
                    f.seek(size, os.SEEK_CUR)
                    if f.tell() > total:
                        raise ReaderError("index record cut short")
                    result.good_end = f.tell()
                elif op == RecordType.CONNECTION:
                    # connection records of an old index: learn them, but drop the old index
                    _add_connection(known, header, Header.read(BytesIO(_rb_reader.read_bytes(f, size))))
                else:
                    f.seek(size, os.SEEK_CUR)
            except (ReaderError, ValueError, OSError, KeyError) as exc:
                result.stopped = f"record at offset {pos}: {exc}"
                break
    result.connections = sorted(known.values(), key=lambda c: c.id)
    for cid in list(result.indexes):
        result.indexes[cid].sort()


def _add_connection(known: Dict[int, Connection], header: Header, conn_header: Header) -> int:
    cid = header.get_uint32("conn")
    if cid not in known:
        latching = conn_header.get("latching")
        known[cid] = Connection(
            cid, _rb_reader.normalize(header.get_string("topic")),
            rosbags_type(conn_header.get_string("type")),
            MessageDefinition(MessageDefinitionFormat.MSG,
                              conn_header.get("message_definition", b"").decode()),
            conn_header.get_string("md5sum"), 0,
            ConnectionExtRosbag1(conn_header["callerid"].decode() if "callerid" in conn_header else None,
                                 int(latching) if latching not in (None, b"") else None),
            None)
    return cid


def _scan_chunk(raw: bytes, pos: int, known: Dict[int, Connection]
                ) -> Tuple[ChunkSummary, Dict[int, List[IndexData]]]:
    """The connection and message records of one decompressed chunk."""
    bio = BytesIO(raw)
    end = len(raw)
    chunk = ChunkSummary(pos, 2**63 - 1, 0, {})
    entries: Dict[int, List[IndexData]] = defaultdict(list)
    while bio.tell() < end:
        offset = bio.tell()
        header = Header.read(bio)
        op = header.get_uint8("op")
        if op == RecordType.CONNECTION:
            _add_connection(known, header, Header.read(bio))
            continue
        size = _rb_reader.read_uint32(bio)
        if op == RecordType.MSGDATA:
            cid = header.get_uint32("conn")
            if cid not in known:
                raise ReaderError(f"message of connection {cid} not preceded by its connection record")
            t = header.get_time("time")
            entries[cid].append(IndexData(t, pos, offset))
            chunk.counts[cid] = chunk.counts.get(cid, 0) + 1
            chunk.start = min(chunk.start, t)
            chunk.end = max(chunk.end, t)
        bio.seek(size, os.SEEK_CUR)
    if bio.tell() != end:
        raise ReaderError("chunk records overrun the chunk")
    return chunk, entries


def _record_op(buf: memoryview, start: int, end: int) -> int:
    """The ``op`` of the record header in ``buf[start:end]`` (-1 when it has none)."""
    while start < end:
        (size,) = _U32.unpack_from(buf, start)
        if buf[start + 4:start + 7] == b"op=":
            return buf[start + 7]
        start += 4 + size
    return -1


class Bag1Reader:
    """A bag v2.0 opened for reading: connections and chunk summaries at once, the message
    index when messages are first read."""

    version = 200

    def __init__(self, path: str, allow_unindexed: bool = False) -> None:
        self.path = Path(path)
        self.indexed = True
        self.scan: Optional[ScanResult] = None
        self._reader = _Reader(self.path)
        try:
            self._reader.open()
        except ReaderError as exc:
            error = _reader_error(exc)
            if not (isinstance(error, ROSBagUnindexedException) and allow_unindexed):
                raise error from None
            self.indexed = False
            self._use_scan(scan_chunks(self.path))
        except OSError as exc:
            raise ROSBagException(f"{exc.strerror or exc}") from None
        self._fill()

    def _use_scan(self, scan: ScanResult) -> None:
        """Read the bag through a scan of its chunks (it has no usable index)."""
        r = self._reader
        if r.bio is None:
            r.bio = self.path.open("rb")
        self.scan = scan
        r.connections = scan.connections
        r.chunk_infos = [ChunkInfo(c.pos, c.start, c.end + 1, c.counts) for c in scan.chunks]
        r.chunks = {c.pos: Chunk(scan.datapos[c.pos][1], scan.datapos[c.pos][0],
                                 _rb_reader.decompressors[c.compression]) for c in scan.chunks}
        r.chunk_meta = {c.pos: (c.compression, c.uncompressed_size, c.compressed_size)
                        for c in scan.chunks}
        r.indexes = {c.id: scan.indexes.get(c.id, []) for c in scan.connections}
        r.index_loaded = True

    def _fill(self) -> None:
        r = self._reader
        self.connections: Dict[int, ConnInfo] = {c.id: _conn_info(c) for c in r.connections}
        self.chunks: List[ChunkSummary] = []
        for info in r.chunk_infos:
            compression, size, datasize = r.chunk_meta.get(info.pos, (Compression.NONE, 0, 0))
            self.chunks.append(ChunkSummary(info.pos, info.start_time, info.end_time - 1,
                                            dict(info.connection_counts), compression, datasize, size))

    def time_range(self) -> Optional[Tuple[int, int]]:
        """(first, last) receive time in ns of the bag's messages; None if it has none."""
        return chunks_time_range(self.chunks)

    def reindex(self, progress: Optional[Callable[[int], None]] = None) -> ScanResult:
        scan = scan_chunks(self.path, progress)
        self._use_scan(scan)
        self._fill()
        return scan

    @property
    def index_loaded(self) -> bool:
        return self._reader.index_loaded

    def index_times(self, conn_ids: List[int]) -> List[int]:
        """Receive times of the messages of these connections, in order (for frequencies)."""
        import heapq

        self._reader.load_index()
        return [e.time for e in heapq.merge(*(self._reader.indexes.get(c, []) for c in conn_ids))]

    def messages(self, conn_ids: Optional[List[int]], start: Optional[int],
                 end: Optional[int]) -> Iterator[Tuple[int, int, Any, Tuple[int, int]]]:
        """(connection id, time ns, serialized bytes, position) in time order; times inclusive.

        The bytes are a memoryview into the decompressed chunk. rosbags' ``Reader.messages``
        parses every record header and copies every message; the index already says where
        each message is and to which connection and time it belongs, so this loop only steps
        over the record header (and any CONNECTION record before it) and slices the data."""
        r = self._reader
        r.load_index()
        assert r.bio is not None
        entries: List[Tuple[int, int, int, int]] = []
        for conn in r.connections:
            if conn_ids is not None and conn.id not in conn_ids:
                continue
            index = r.indexes.get(conn.id, [])  # sorted by time
            lo = 0 if start is None else bisect.bisect_left(index, (start,))
            hi = len(index) if end is None else bisect.bisect_right(index, (end,))
            part = index[lo:hi]
            # (time, chunk_pos, offset, connection) built by C-level iterators, not per-entry Python
            entries.extend(zip(map(_by_time, part), map(_chunk_pos, part), map(_offset, part),
                               itertools.repeat(conn.id)))
        entries.sort(key=_by_time)  # stable: equal times keep the connection order, as heapq.merge
        bio = r.bio
        current = -1
        buf = memoryview(b"")
        for t, chunk_pos, offset, cid in entries:
            if chunk_pos != current:
                chunk = r.chunks[chunk_pos]
                bio.seek(chunk.datapos)
                data = bio.read(chunk.datasize)
                if len(data) != chunk.datasize:
                    raise ROSBagFormatException(f"chunk at {chunk_pos} is cut short")
                buf = memoryview(chunk.decompressor(data))
                current = chunk_pos
            try:
                while True:
                    (hlen,) = _U32.unpack_from(buf, offset)
                    dpos = offset + 4 + hlen
                    (dlen,) = _U32.unpack_from(buf, dpos)
                    if _record_op(buf, offset + 4, dpos) != RecordType.CONNECTION:
                        break
                    offset = dpos + 4 + dlen  # a CONNECTION record before the message
            except struct.error:
                raise ROSBagFormatException(f"index entry points past chunk at {chunk_pos}") from None
            yield cid, t, buf[dpos + 4:dpos + 4 + dlen], (chunk_pos, offset)

    def close(self) -> None:
        if self._reader.bio is not None:
            self._reader.close()


class _Count:
    """Stands for an index list of which rosbags' ``Writer.close`` only needs the length."""

    __slots__ = ("n",)

    def __init__(self, n: int) -> None:
        self.n = n

    def __len__(self) -> int:
        return self.n


_COMPRESSION_FORMATS = {Compression.BZ2: _rb_writer.Writer.CompressionFormat.BZ2,
                        Compression.LZ4: _rb_writer.Writer.CompressionFormat.LZ4}


def _roslz4_compress(data: bytes) -> bytes:
    """An LZ4 frame ROS's roslz4 can read: rosbags' frames store the content size, a header
    field roslz4 rejects ("malformed data"), so the frame is written without it."""
    import lz4.frame

    return lz4.frame.compress(data, compression_level=0, content_checksum=True, store_size=False)


def _set_compression(w: _rb_writer.Writer, compression: str) -> None:
    w.set_compression(_COMPRESSION_FORMATS[compression])
    if compression == Compression.LZ4:
        w.compressor = _roslz4_compress


class Bag1Writer:
    """A bag v2.0 being written: rosbags' ``Writer`` with one connection per distinct header,
    chunks closed by size or on request (``flush_chunk``), and data handed to the kernel after
    each chunk so that a killed process loses only its open chunk."""

    def __init__(self, path: str, compression: str = Compression.NONE,
                 chunk_threshold: int = 768 * 1024, *, existing: Optional[ScanResult] = None,
                 bio: Any=None) -> None:
        self.path = Path(path)
        self.compression = compression
        if existing is None:
            if self.path.exists() or self.path.is_symlink():
                self.path.unlink()  # rosbag truncates; rosbags refuses an existing file
            self._w = _rb_writer.Writer(self.path)
            if compression != Compression.NONE:
                _set_compression(self._w, compression)
            self._w.open()
            self._w.bio.flush()  # the file header reaches the kernel before any message
        else:
            self._w = self._reopen(bio, existing, compression)
        self._w.chunk_threshold = chunk_threshold
        self._by_key: Dict[tuple, Connection] = {c[1:7]: c for c in self._w.connections}
        self.connections: Dict[int, ConnInfo] = {c.id: _conn_info(c) for c in self._w.connections}

    def _reopen(self, bio: Any, existing: ScanResult, compression: str) -> _rb_writer.Writer:
        w = object.__new__(_rb_writer.Writer)
        w.path = self.path
        w.bio = None
        w.compressor = lambda x: x
        w.compression_format = "none"
        if compression != Compression.NONE:
            _set_compression(w, compression)
        conns = [c._replace(owner=w) for c in existing.connections]
        if [c.id for c in conns] != list(range(len(conns))):
            raise ROSBagException("cannot append to a bag whose connection ids are not 0..N-1")
        w.connections = conns
        w.chunks = [_rb_writer.WriteChunk(BytesIO(), c.pos, c.start, c.end,
                                          {cid: _Count(n) for cid, n in c.counts.items()})
                    for c in existing.chunks]
        w.chunks.append(_rb_writer.WriteChunk(BytesIO(), -1, _rb_writer.MAXSIZE, 0, defaultdict(list)))
        w.chunk_threshold = 768 * 1024
        # cut off the old index (and anything damaged) and mark the bag unindexed until close
        bio.seek(existing.good_end)
        bio.truncate()
        bio.seek(len(MAGIC))
        header = _rb_writer.Header()
        header.set_uint64("index_pos", 0)
        header.set_uint32("conn_count", 0)
        header.set_uint32("chunk_count", 0)
        size = header.write(bio, RecordType.BAGHEADER)
        pad = FILE_HEADER_LENGTH - 4 - size
        bio.write(_rb_writer.serialize_uint32(pad) + b" " * pad)
        bio.seek(0, os.SEEK_END)
        w.bio = bio
        return w

    @classmethod
    def append(cls, path: str, compression: str = Compression.NONE,
               chunk_threshold: int = 768 * 1024, scan: Optional[ScanResult] = None) -> Bag1Writer:
        """Open an existing bag to add messages (``scan`` when its index is missing)."""
        if scan is None:
            scan = summary_scan(path)
        bio = open(path, "r+b")
        try:
            return cls(path, compression, chunk_threshold, existing=scan, bio=bio)
        except BaseException:
            bio.close()
            raise

    def connection(self, topic: str, datatype: str, md5sum: str, msg_def: str,
                   callerid: Optional[str] = None, latching: Optional[str] = None) -> int:
        """The id of the connection with this header, added on first use."""
        latch = int(latching) if latching not in (None, "") else None
        msgtype = rosbags_type(datatype)
        key = (topic, msgtype, MessageDefinition(MessageDefinitionFormat.MSG, msg_def), md5sum,
               0, ConnectionExtRosbag1(callerid, latch))
        conn = self._by_key.get(key)
        if conn is None:
            conn = self._w.add_connection(topic, msgtype, msgdef=msg_def, md5sum=md5sum,
                                          callerid=callerid, latching=latch)
            self._by_key[key] = conn
            self.connections[conn.id] = ConnInfo(conn.id, topic, datatype, md5sum, msg_def,
                                                 callerid, None if latch is None else str(latch))
        return conn.id

    def write(self, conn_id: int, t_ns: int, data: Any) -> None:
        self._w.write(self._w.connections[conn_id], t_ns, data)

    @property
    def chunk_open_bytes(self) -> int:
        return self._w.chunks[-1].data.tell()

    def flush_chunk(self) -> None:
        """Close the open chunk (with its index records) and hand the file to the kernel."""
        chunk = self._w.chunks[-1]
        if chunk.connections:
            self._w.write_chunk(chunk)
        self._w.bio.flush()

    def tell(self) -> int:
        """Bytes in the file plus those waiting in the open chunk."""
        return self._w.bio.tell() + self._w.chunks[-1].data.tell()

    def chunk_summaries(self) -> List[ChunkSummary]:
        return [ChunkSummary(c.pos, c.start, c.end, {k: len(v) for k, v in c.connections.items()},
                             self.compression) for c in self._w.chunks if c.pos != -1]

    def close(self) -> None:
        if self._w.bio is not None:
            self._w.close()

    def abort(self) -> None:
        self._w.abort()


def summary_scan(path: str) -> ScanResult:
    """The connections and chunks of an indexed bag, from its index (for appending)."""
    reader = _Reader(Path(path))
    try:
        reader.open()
    except ReaderError as exc:
        raise _reader_error(exc) from None
    try:
        result = ScanResult()
        result.connections = list(reader.connections)
        for info in reader.chunk_infos:
            result.chunks.append(ChunkSummary(info.pos, info.start_time, info.end_time - 1,
                                              dict(info.connection_counts)))
        result.good_end = _index_pos(reader)
        return result
    finally:
        reader.close()


def _index_pos(reader: _Reader) -> int:
    assert reader.bio
    reader.bio.seek(len(MAGIC))
    return Header.read(reader.bio, RecordType.BAGHEADER).get_uint64("index_pos")


def reindex_in_place(path: str, progress: Optional[Callable[[int], None]] = None) -> ScanResult:
    """Rebuild the index of the bag at ``path``: cut what follows the last whole chunk, then
    write connections, chunk infos and the file header (``rosbag reindex``)."""
    scan = scan_chunks(Path(path), progress)
    writer = Bag1Writer.append(path, scan=scan)
    writer.close()
    return scan
