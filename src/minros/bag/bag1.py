"""Bag format 2.0: reading, writing, appending, reindexing.

rosbags (Ternaris) writes the chunks and the messages in them; minros adds what it lacks or
does differently:

* **reading**: the index (connections, chunk infos, chunk headers) is read on open, the
  INDEX_DATA records only when messages are first read (``rosbag info`` does not need them,
  and a bag of millions of small messages has millions of entries); every record goes
  through :mod:`minros.bag.records`, so a damaged file gives rosbag's exceptions, never
  another kind.
* **writing**: the file header in ROS's layout and the index (:mod:`minros.bag.records`), as
  rosbags pads the file header differently (a ROS tool rewriting it would damage the first
  chunk); connections may have any ids, as bags another writer appended to have.
* **reindexing** (:mod:`minros.bag.scan`) a bag whose index is missing or damaged.
* **appending**: rosbags' ``Writer`` only creates new files, so it is handed the existing
  file, positioned after its last chunk, with the connections and chunks that file has.
"""

from __future__ import annotations

import bisect
import itertools
import operator
import os
import struct
from collections import defaultdict
from dataclasses import dataclass
from io import BytesIO
from pathlib import Path
from typing import Any, BinaryIO, Callable, Dict, Iterator, List, Optional, Tuple, Union

from rosbags.interfaces import (
    Connection,
    ConnectionExtRosbag1,
    MessageDefinition,
    MessageDefinitionFormat,
)
from rosbags.rosbag1 import writer as _rb_writer
from rosbags.rosbag1.reader import IndexData, decompressors
from rosbags.typesys.msg import denormalize_msgtype

from minros.bag import records
from minros.bag.errors import (
    Compression,
    ROSBagEncryptNotSupportedException,
    ROSBagException,
    ROSBagFormatException,
    ROSBagUnindexedException,
)
from minros.bag.records import DATA_START, FILE_HEADER_LENGTH, MAGIC, Damage  # noqa: F401
from minros.bag.scan import (  # noqa: F401 - the names bag1 has always offered
    ChunkSummary,
    ScanResult,
    iter_scan,
    parse_connection,
    reindex_in_place,
    rosbags_type,
    scan_chunks,
)
from minros.bag.scan import check_version as _check_version

_U32 = struct.Struct("<I")
_by_time = operator.itemgetter(0)
_chunk_pos = operator.itemgetter(1)
_offset = operator.itemgetter(2)
#: what parsing a damaged file can raise besides :class:`Damage` (struct on short buffers,
#: int() and decode() on garbage, seek() on offsets beyond 2**63, the decompressors' own kinds)
DAMAGE_ERRORS = (Damage, ValueError, struct.error, OverflowError, KeyError, IndexError,
                 EOFError, RuntimeError, OSError)


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


def chunks_time_range(chunks: List[ChunkSummary]) -> Optional[Tuple[int, int]]:
    """(first, last) receive time in ns of the messages in ``chunks``; None if they have none."""
    full = [c for c in chunks if c.counts]
    if not full:
        return None
    return min(c.start for c in full), max(c.end for c in full)


def ros1_type(msgtype: str) -> str:
    """``std_msgs/msg/String`` (rosbags' spelling) -> ``std_msgs/String``."""
    return denormalize_msgtype(msgtype) if "/msg/" in msgtype else msgtype


def _conn_info(conn: Connection) -> ConnInfo:
    ext = conn.ext
    latching = None
    if isinstance(ext, ConnectionExtRosbag1) and ext.latching is not None:
        latching = str(ext.latching)
    return ConnInfo(conn.id, conn.topic, ros1_type(conn.msgtype), conn.digest, conn.msgdef.data,
                    ext.callerid if isinstance(ext, ConnectionExtRosbag1) else None, latching)


Source = Union[str, os.PathLike, BinaryIO]


def _open(source: Source, mode: str) -> Tuple[BinaryIO, Optional[Path]]:
    """(file object, path): the file a path names, opened; or the file object given."""
    if isinstance(source, (str, os.PathLike)):
        try:
            return open(source, mode), Path(source)  # noqa: SIM115 - closed by the bag
        except OSError as exc:
            raise ROSBagException(f"{exc.strerror or exc}: '{os.fspath(source)}'") from None
    return source, None


class _Index:
    """The index of a bag v2.0 file: read on open from the records after the chunks (and each
    chunk's header, for its compression and sizes); the INDEX_DATA records on first use."""

    def __init__(self, bio: BinaryIO) -> None:
        self.bio = bio
        self.size = bio.seek(0, os.SEEK_END)
        self.connections: List[Connection] = []
        self.chunks: List[ChunkSummary] = []
        #: chunk position -> (data position, data size, decompressor)
        self.chunk_data: Dict[int, Tuple[int, int, Callable[[bytes], bytes]]] = {}
        self.indexes: Dict[int, List[IndexData]] = {}
        self.index_loaded = False
        self.index_pos = 0
        self.data_start = DATA_START

    def open(self) -> None:
        """Read the index. Raises ROSBagException for a file that is not a bag,
        ROSBagUnindexedException for one without an index, and :data:`DAMAGE_ERRORS` for a
        damaged one."""
        f = self.bio
        f.seek(0)
        try:
            version = records.read_version(f)
        except ValueError as exc:
            raise ROSBagException(str(exc)) from None
        if version // 100 != 2:
            raise ROSBagException(f"bag version {version} is not supported by minros (it reads 2.0)")
        fields, datapos, dlen = records.read_record_header(f, len(MAGIC), self.size)
        if records.u8(fields, "op") != records.OP_FILE_HEADER:
            raise Damage("the first record is not the file header")
        self.data_start = datapos + dlen
        encryptor = fields.get("encryptor")
        if encryptor:
            raise ROSBagEncryptNotSupportedException(
                f"bag encryption {encryptor.decode(errors='replace')!r} is not supported by minros")
        self.index_pos = records.u64(fields, "index_pos")
        conn_count = records.u32(fields, "conn_count")
        chunk_count = records.u32(fields, "chunk_count")
        if self.index_pos == 0:
            raise ROSBagUnindexedException()
        if not self.data_start <= self.index_pos <= self.size:
            raise Damage("the index position is outside the file")
        pos = self.index_pos
        for _ in range(conn_count):
            pos = self._read_connection(pos)
        for _ in range(chunk_count):
            pos = self._read_chunk_info(pos)
        for chunk in self.chunks:
            self._read_chunk_header(chunk)

    def _read_connection(self, pos: int) -> int:
        fields, datapos, dlen = records.read_record_header(self.bio, pos, self.size)
        if records.u8(fields, "op") != records.OP_CONNECTION:
            raise Damage(f"no CONNECTION record at {pos}")
        data = records.parse_fields(self.bio.read(dlen), 0, dlen)
        self.connections.append(parse_connection(fields, data))
        return datapos + dlen

    def _read_chunk_info(self, pos: int) -> int:
        fields, datapos, dlen = records.read_record_header(self.bio, pos, self.size)
        if records.u8(fields, "op") != records.OP_CHUNK_INFO or records.u32(fields, "ver") != 1:
            raise Damage(f"no CHUNK_INFO record at {pos}")
        count = records.u32(fields, "count")
        data = self.bio.read(dlen)
        if len(data) != dlen or dlen != 8 * count:
            raise Damage(f"CHUNK_INFO record at {pos} has a wrong length")
        counts = dict(struct.iter_unpack("<II", data))
        self.chunks.append(ChunkSummary(records.u64(fields, "chunk_pos"),
                                        records.time_ns(fields, "start_time"),
                                        records.time_ns(fields, "end_time"), counts))
        return datapos + dlen

    def _read_chunk_header(self, chunk: ChunkSummary) -> None:
        if not self.data_start <= chunk.pos < self.index_pos:
            raise Damage(f"chunk position {chunk.pos} is outside the chunks")
        fields, datapos, dlen = records.read_record_header(self.bio, chunk.pos, self.index_pos)
        if records.u8(fields, "op") != records.OP_CHUNK:
            raise Damage(f"no CHUNK record at {chunk.pos}")
        chunk.compression = records.text(fields, "compression")
        decompressor = decompressors.get(chunk.compression)
        if decompressor is None:
            raise ROSBagFormatException(f"unsupported compression type: {chunk.compression}")
        chunk.uncompressed_size = records.u32(fields, "size")
        chunk.compressed_size = dlen
        self.chunk_data[chunk.pos] = (datapos, dlen, decompressor)

    def load_index(self) -> None:
        """Read the INDEX_DATA records after each chunk (one per connection in the chunk)."""
        if self.index_loaded:
            return
        indexes: Dict[int, List[IndexData]] = defaultdict(list)
        for chunk in self.chunks:
            try:
                datapos, dlen, _d = self.chunk_data[chunk.pos]
                pos = datapos + dlen
                for _ in range(len(chunk.counts)):
                    fields, ipos, ilen = records.read_record_header(self.bio, pos, self.size)
                    if records.u8(fields, "op") != records.OP_IDXDATA:
                        raise Damage("a connection's INDEX_DATA record is missing")
                    cid, items = records.read_index_entries(fields, self.bio.read(ilen))
                    indexes[cid].extend(IndexData(t, chunk.pos, offset) for t, offset in items)
                    pos = ipos + ilen
            except DAMAGE_ERRORS as exc:
                raise ROSBagFormatException(f"the index of the chunk at offset {chunk.pos} is "
                                            f"damaged ({exc}): run rosbag reindex") from None
        self.indexes = {c.id: sorted(indexes[c.id]) for c in self.connections}
        self.index_loaded = True


def _record_op(buf: memoryview, start: int, end: int) -> int:
    """The ``op`` of the record header in ``buf[start:end]`` (-1 when it has none)."""
    while start < end:
        (size,) = _U32.unpack_from(buf, start)
        if buf[start + 4:start + 7] == b"op=":
            return buf[start + 7]
        start += 4 + size
    return -1


def check_version(source: Source) -> None:
    """Raise rosbag's ROSBagException unless ``source`` is a bag of format 2.x (cheap: the
    first line only)."""
    bio, path = _open(source, "rb")
    try:
        _check_version(bio)
    finally:
        if path is not None:
            bio.close()


class Bag1Reader:
    """A bag v2.0 opened for reading: connections and chunk summaries at once, the message
    index when messages are first read."""

    version = 200

    def __init__(self, source: Source, allow_unindexed: bool = False, keep_open: bool = False) -> None:
        bio, self.path = _open(source, "rb")
        self._keep_open = keep_open
        self.indexed = True
        self.scan: Optional[ScanResult] = None
        self._index = _Index(bio)
        try:
            try:
                self._index.open()
            except ROSBagUnindexedException:
                if not allow_unindexed:
                    raise
                self._use_scan(scan_chunks(bio))
            except ROSBagException:
                raise
            except DAMAGE_ERRORS:
                # as rosbag: an index that is cut short or damaged means "run rosbag reindex"
                if not allow_unindexed:
                    raise ROSBagUnindexedException() from None
                self._use_scan(scan_chunks(bio))
        except BaseException:
            if not keep_open:
                bio.close()  # rosbag closes the file, the one it was given too
            raise
        self._fill()

    def _use_scan(self, scan: ScanResult) -> None:
        """Read the bag through a scan of its chunks (its index is missing or damaged)."""
        r = self._index
        self.indexed = False
        self.scan = scan
        r.connections = scan.connections
        r.chunks = scan.chunks
        r.chunk_data = {c.pos: (*scan.datapos[c.pos], decompressors[c.compression]) for c in scan.chunks}
        r.indexes = {c.id: scan.indexes.get(c.id, []) for c in scan.connections}
        r.index_loaded = True

    def _fill(self) -> None:
        self.connections: Dict[int, ConnInfo] = {c.id: _conn_info(c) for c in self._index.connections}
        self.chunks: List[ChunkSummary] = self._index.chunks

    def time_range(self) -> Optional[Tuple[int, int]]:
        """(first, last) receive time in ns of the bag's messages; None if it has none."""
        return chunks_time_range(self.chunks)

    def reindex(self, progress: Optional[Callable[[int], None]] = None) -> ScanResult:
        scan = scan_chunks(self._index.bio, progress)
        self._use_scan(scan)
        self._fill()
        return scan

    @property
    def index_loaded(self) -> bool:
        return self._index.index_loaded

    def index_times(self, conn_ids: List[int]) -> List[int]:
        """Receive times of the messages of these connections, in order (for frequencies)."""
        import heapq

        self._index.load_index()
        return [e.time for e in heapq.merge(*(self._index.indexes.get(c, []) for c in conn_ids))]

    def messages(self, conn_ids: Optional[List[int]], start: Optional[int],
                 end: Optional[int]) -> Iterator[Tuple[int, int, Any, Tuple[int, int]]]:
        """(connection id, time ns, serialized bytes, position) in time order; times inclusive.

        The bytes are a memoryview into the decompressed chunk. The index says where each
        message is and to which connection and time it belongs, so this loop only steps over
        the record header (and any CONNECTION record before it) and slices the data; what it
        finds there is checked, and damage raises ROSBagFormatException."""
        r = self._index
        r.load_index()
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
        current = -1
        buf = memoryview(b"")
        for t, chunk_pos, offset, cid in entries:
            if chunk_pos != current:
                buf = memoryview(self._chunk(chunk_pos))
                current = chunk_pos
            size = len(buf)
            try:
                while True:
                    (hlen,) = _U32.unpack_from(buf, offset)
                    dpos = offset + 4 + hlen
                    (dlen,) = _U32.unpack_from(buf, dpos)
                    op = _record_op(buf, offset + 4, dpos)
                    if op != records.OP_CONNECTION:
                        break
                    offset = dpos + 4 + dlen  # a CONNECTION record before the message
            except struct.error:
                op = -1
            if op != records.OP_MSGDATA or dpos + 4 + dlen > size:
                raise ROSBagFormatException(
                    f"the index points to no message in the chunk at offset {chunk_pos}: the bag "
                    "is damaged (run rosbag reindex)")
            yield cid, t, buf[dpos + 4:dpos + 4 + dlen], (chunk_pos, offset)

    def _chunk(self, pos: int) -> bytes:
        """The decompressed data of the chunk at ``pos``."""
        datapos, datasize, decompress = self._index.chunk_data[pos]
        bio = self._index.bio
        bio.seek(datapos)
        data = bio.read(datasize)
        if len(data) != datasize:
            raise ROSBagFormatException(f"the chunk at offset {pos} is cut short: run rosbag reindex")
        try:
            return decompress(data)
        except Exception as exc:  # noqa: BLE001 - lz4, bz2 each raise their own kinds
            raise ROSBagFormatException(f"the chunk at offset {pos} is damaged ({type(exc).__name__}: "
                                        f"{exc}): run rosbag reindex to keep the others") from None

    @property
    def file(self) -> BinaryIO:
        """The open bag file."""
        return self._index.bio

    def close(self) -> None:
        if not self._keep_open:
            self._index.bio.close()


class _Count:
    """Stands for an index list of which only the length is needed (chunks already written)."""

    __slots__ = ("n",)

    def __init__(self, n: int) -> None:
        self.n = n

    def __len__(self) -> int:
        return self.n


_COMPRESSION_FORMATS = {Compression.BZ2: _rb_writer.Writer.CompressionFormat.BZ2,
                        Compression.LZ4: _rb_writer.Writer.CompressionFormat.LZ4}


def _roslz4_compress(data: bytes) -> bytes:
    """An LZ4 frame ROS's roslz4 can read. roslz4 rejects ("malformed data") frames that store
    the content size (as rosbags' do), have block checksums, or link each block to the one
    before (lz4's default), so the frame has none of these; its blocks are 1 MB, as roslz4's."""
    import lz4.frame

    return lz4.frame.compress(data, compression_level=0, content_checksum=True, store_size=False,
                              block_linked=False, block_checksum=False,
                              block_size=lz4.frame.BLOCKSIZE_MAX1MB)


def _rosbags_writer(path: Optional[Path], bio: BinaryIO, chunk_threshold: int,
                    connections: List[Connection], chunks: List[Any]) -> _rb_writer.Writer:
    """rosbags' ``Writer`` on an open file, with the connections and chunks it already holds
    (its constructor only creates new files). Its ``write`` and ``write_chunk`` are used; the
    file header and the index are minros's (:func:`records.write_index`)."""
    w = object.__new__(_rb_writer.Writer)
    w.path = path
    w.bio = None
    w.compressor = lambda x: x
    w.compression_format = "none"
    w.connections = connections
    w.chunks = chunks + [_rb_writer.WriteChunk(BytesIO(), -1, _rb_writer.MAXSIZE, 0, defaultdict(list))]
    w.chunk_threshold = chunk_threshold
    w.bio = bio
    return w


class Bag1Writer:
    """A bag v2.0 being written: rosbags' ``Writer`` with one connection per distinct header,
    chunks closed by size or on request (``flush_chunk``), and data handed to the kernel after
    each chunk so that a killed process loses only its open chunk."""

    def __init__(self, target: Source, compression: str = Compression.NONE,
                 chunk_threshold: int = 768 * 1024, *, existing: Optional[ScanResult] = None,
                 keep_open: bool = False) -> None:
        self.compression = compression
        self._keep_open = keep_open
        if existing is None:
            bio, self.path = _open(target, "w+b")  # rosbag truncates an existing file
            self.data_start = DATA_START
            self._w = _rosbags_writer(self.path, bio, chunk_threshold, [], [])
            self.set_compression(compression)
            try:
                bio.write(MAGIC + records.file_header_record(0, 0, 0))
                bio.flush()  # the file header reaches the kernel before any message
            except BaseException:
                if not keep_open:
                    bio.close()
                raise
        else:
            bio, self.path = _open(target, "r+b")
            self._w = self._reopen(bio, existing, compression, chunk_threshold)
        self._conns: Dict[int, Connection] = {c.id: c for c in self._w.connections}
        self._by_key: Dict[tuple, Connection] = {self._key(c): c for c in self._w.connections}
        self.connections: Dict[int, ConnInfo] = {c.id: _conn_info(c) for c in self._w.connections}

    @property
    def file(self) -> Optional[BinaryIO]:
        """The open bag file (None once closed)."""
        return self._w.bio

    @staticmethod
    def _key(conn: Connection) -> tuple:
        return (conn.topic, conn.msgtype, conn.msgdef, conn.digest, conn.ext)

    def _reopen(self, bio: BinaryIO, existing: ScanResult, compression: str,
                chunk_threshold: int) -> _rb_writer.Writer:
        self.data_start = existing.data_start
        chunks = [_rb_writer.WriteChunk(BytesIO(), c.pos, c.start, c.end,
                                        {cid: _Count(n) for cid, n in c.counts.items()})
                  for c in existing.chunks]
        w = self._w = _rosbags_writer(self.path, bio, chunk_threshold, [], chunks)
        w.connections = [c._replace(owner=w) for c in existing.connections]
        self.set_compression(compression)
        # cut off the old index (and anything damaged) and mark the bag unindexed until close
        bio.seek(existing.good_end)
        bio.truncate()
        bio.seek(0)
        bio.write(MAGIC + records.file_header_record(0, 0, 0, self.data_start - len(MAGIC) - 8))
        bio.seek(0, os.SEEK_END)
        return w

    @classmethod
    def append(cls, target: Source, compression: str = Compression.NONE,
               chunk_threshold: int = 768 * 1024, scan: Optional[ScanResult] = None,
               keep_open: bool = False) -> Bag1Writer:
        """Open an existing bag to add messages (``scan`` when its index is missing)."""
        if scan is None:
            scan = summary_scan(target)
        return cls(target, compression, chunk_threshold, existing=scan, keep_open=keep_open)

    def connection(self, topic: str, datatype: str, md5sum: str, msg_def: str,
                   callerid: Optional[str] = None, latching: Optional[str] = None) -> int:
        """The id of the connection with this header, added on first use."""
        latch = int(latching) if latching not in (None, "") else None
        conn = Connection(max(self._conns, default=-1) + 1, topic, rosbags_type(datatype),
                          MessageDefinition(MessageDefinitionFormat.MSG, msg_def), md5sum, 0,
                          ConnectionExtRosbag1(callerid, latch), self._w)
        known = self._by_key.get(self._key(conn))
        if known is not None:
            return known.id
        # the CONNECTION record goes into the open chunk, before the connection's first message
        self._w.chunks[-1].data.write(records.connection_record(conn))
        self._w.connections.append(conn)
        self._conns[conn.id] = self._by_key[self._key(conn)] = conn
        self.connections[conn.id] = ConnInfo(conn.id, topic, datatype, md5sum, msg_def,
                                             callerid, None if latch is None else str(latch))
        return conn.id

    def write(self, conn_id: int, t_ns: int, data: Any) -> None:
        self._w.write(self._conns[conn_id], t_ns, data)

    def set_compression(self, compression: str) -> None:
        """Compress the chunks still to come with ``compression`` (a bag may mix them)."""
        if compression == Compression.NONE:
            self._w.compressor, self._w.compression_format = (lambda x: x), "none"
        else:
            bio, self._w.bio = self._w.bio, None  # rosbags sets it only on a writer not open
            try:
                self._w.set_compression(_COMPRESSION_FORMATS[compression])
                if compression == Compression.LZ4:
                    self._w.compressor = _roslz4_compress
            finally:
                self._w.bio = bio
        self.compression = compression

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
        """Write the open chunk, the index and the file header, and close the file."""
        w = self._w
        if w.bio is None:
            return
        bio = w.bio
        try:
            if w.chunks[-1].data.tell():
                w.write_chunk(w.chunks[-1])
            index = [(c.pos, 0 if c.start == _rb_writer.MAXSIZE else c.start, c.end,
                      {cid: len(items) for cid, items in c.connections.items()})
                     for c in w.chunks if c.pos != -1]
            records.write_index(bio, w.connections, index, self.data_start)
        finally:
            w.bio = None
            if self._keep_open:
                bio.flush()
            else:
                bio.close()

    def abort(self) -> None:
        bio, self._w.bio = self._w.bio, None
        if bio is not None and not self._keep_open:
            bio.close()


def summary_scan(source: Source) -> ScanResult:
    """The connections and chunks of an indexed bag, from its index (for appending)."""
    bio, path = _open(source, "rb")
    index = _Index(bio)
    try:
        try:
            index.open()
        except ROSBagException:
            raise
        except DAMAGE_ERRORS:
            raise ROSBagUnindexedException() from None
        result = ScanResult()
        result.connections = list(index.connections)
        result.chunks = list(index.chunks)
        result.good_end = index.index_pos
        result.data_start = index.data_start
        return result
    finally:
        if path is not None:
            bio.close()
