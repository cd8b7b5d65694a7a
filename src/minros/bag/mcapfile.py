"""MCAP files with the ``ros1`` profile, through the ``mcap`` library.

A connection is a channel: its schema is named after the message type with encoding
``ros1msg`` and the message definition as data; messages are encoded ``ros1`` (the TCPROS
bytes); the channel metadata keeps the publisher's ``md5sum``, ``callerid`` and ``latching``,
as the profile specifies. The same reader and writer interface as :mod:`minros.bag.bag1`.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any, Dict, Iterator, List, Optional, Tuple

from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader, make_reader
from mcap.writer import CompressionType, Writer

from minros.bag.bag1 import ChunkSummary, ConnInfo
from minros.bag.errors import ROSBagException, ROSBagFormatException, ROSBagUnindexedException

#: what the mcap library raises on a damaged file besides its own McapError (struct on short
#: records, the decompressors' kinds)
_DAMAGE = (McapError, ValueError, EOFError, OSError, struct.error, KeyError, IndexError, RuntimeError)

PROFILE = "ros1"
SCHEMA_ENCODING = "ros1msg"
MESSAGE_ENCODING = "ros1"

_COMPRESSION = {"none": CompressionType.NONE, "lz4": CompressionType.LZ4,
                "zstd": CompressionType.ZSTD, "bz2": CompressionType.ZSTD}


def _conn(channel: Any, schema: Any) -> ConnInfo:
    meta = channel.metadata or {}
    return ConnInfo(channel.id, channel.topic, schema.name if schema else "",
                    meta.get("md5sum", "*"),
                    schema.data.decode("utf-8", "replace") if schema else "",
                    meta.get("callerid"), meta.get("latching"))


class McapReader:
    """An MCAP file opened for reading through its summary section."""

    version = "mcap"

    def __init__(self, path: str, allow_unindexed: bool = False) -> None:
        self.path = Path(path)
        self.indexed = True
        try:
            self._f = open(path, "rb")
        except OSError as exc:
            raise ROSBagException(str(exc.strerror or exc)) from None
        try:
            self._reader = make_reader(self._f)
            try:
                summary = self._reader.get_summary()
            except _DAMAGE:
                summary = None  # cut short or damaged: no usable summary
            if summary is None or summary.statistics is None:
                if not allow_unindexed:
                    raise ROSBagUnindexedException()
                self._load_by_streaming()
            else:
                self._load_summary(summary)
        except _DAMAGE as exc:
            self._f.close()
            raise ROSBagFormatException(f"not a readable MCAP file: {exc}") from None
        except BaseException:
            self._f.close()
            raise

    def _load_summary(self, summary: Any) -> None:
        self.connections: Dict[int, ConnInfo] = {
            cid: _conn(ch, summary.schemas.get(ch.schema_id)) for cid, ch in summary.channels.items()}
        stats = summary.statistics
        self.counts = dict(stats.channel_message_counts)
        self.start = stats.message_start_time
        self.end = stats.message_end_time
        self.chunks = [ChunkSummary(ci.chunk_start_offset, ci.message_start_time, ci.message_end_time,
                                    {}, ci.compression or "none", ci.compressed_size,
                                    ci.uncompressed_size) for ci in summary.chunk_indexes]
        self._streamed: Optional[List[Tuple[int, int, bytes]]] = None

    def _load_by_streaming(self) -> None:
        """A file without summary (its writer died): read the records that are whole."""
        self.indexed = False
        self._f.seek(0)
        self.connections = {}
        self.counts: Dict[int, int] = {}
        self.chunks = []
        streamed: List[Tuple[int, int, bytes]] = []
        try:
            for schema, channel, message in NonSeekingReader(self._f).iter_messages(log_time_order=False):
                if channel.id not in self.connections:
                    self.connections[channel.id] = _conn(channel, schema)
                self.counts[channel.id] = self.counts.get(channel.id, 0) + 1
                streamed.append((message.log_time, channel.id, message.data))
        except _DAMAGE:
            pass  # the damaged tail
        streamed.sort(key=lambda m: m[0])
        self._streamed = streamed
        self.start = streamed[0][0] if streamed else 0
        self.end = streamed[-1][0] if streamed else 0

    index_loaded = True

    def time_range(self) -> Optional[Tuple[int, int]]:
        """(first, last) log time in ns of the file's messages; None if it has none."""
        return (self.start, self.end) if any(self.counts.values()) else None

    def index_times(self, conn_ids: List[int]) -> List[int]:
        return [t for _c, t, _d, _p in self.messages(conn_ids, None, None)]

    def messages(self, conn_ids: Optional[List[int]], start: Optional[int],
                 end: Optional[int]) -> Iterator[Tuple[int, int, bytes, Tuple[int, int]]]:
        wanted = None if conn_ids is None else set(conn_ids)
        if self._streamed is not None:
            for t, cid, data in self._streamed:
                if (wanted is None or cid in wanted) and (start is None or t >= start) \
                        and (end is None or t <= end):
                    yield cid, t, data, (0, 0)
            return
        topics = None if wanted is None else sorted({self.connections[c].topic for c in wanted})
        try:
            for _schema, channel, message in self._reader.iter_messages(
                    topics=topics, starting_at=start, ending_at=end, log_time_order=True):
                if wanted is None or channel.id in wanted:
                    yield channel.id, message.log_time, message.data, (0, 0)
        except _DAMAGE as exc:
            raise ROSBagFormatException(f"the MCAP file is damaged ({type(exc).__name__}: {exc})") from None

    def close(self) -> None:
        self._f.close()


class McapWriter:
    """An MCAP file being written (profile ``ros1``), chunks closed on size or on request."""

    def __init__(self, path: str, compression: str = "none", chunk_threshold: int = 768 * 1024) -> None:
        self.path = Path(path)
        self.compression = compression
        self._f = open(path, "wb")
        self._w = Writer(self._f, chunk_size=chunk_threshold,
                         compression=_COMPRESSION.get(compression, CompressionType.NONE))
        self._w.start(profile=PROFILE, library="minros")
        self._schemas: Dict[Tuple[str, str], int] = {}
        self._by_key: Dict[tuple, int] = {}
        self.connections: Dict[int, ConnInfo] = {}
        self._seq: Dict[int, int] = {}
        self._open_bytes = 0
        self._chunks: List[ChunkSummary] = []

    def connection(self, topic: str, datatype: str, md5sum: str, msg_def: str,
                   callerid: Optional[str] = None, latching: Optional[str] = None) -> int:
        key = (topic, datatype, md5sum, msg_def, callerid, latching)
        cid = self._by_key.get(key)
        if cid is not None:
            return cid
        schema_id = self._schemas.get((datatype, msg_def))
        if schema_id is None:
            schema_id = self._w.register_schema(datatype, SCHEMA_ENCODING, msg_def.encode())
            self._schemas[(datatype, msg_def)] = schema_id
        meta = {"md5sum": md5sum}
        if callerid is not None:
            meta["callerid"] = callerid
        if latching is not None:
            meta["latching"] = latching
        cid = self._w.register_channel(topic, MESSAGE_ENCODING, schema_id, meta)
        self._by_key[key] = cid
        self.connections[cid] = ConnInfo(cid, topic, datatype, md5sum, msg_def, callerid, latching)
        return cid

    def write(self, conn_id: int, t_ns: int, data: Any) -> None:
        seq = self._seq.get(conn_id, 0)
        self._seq[conn_id] = seq + 1
        self._w.add_message(conn_id, log_time=t_ns, data=bytes(data), publish_time=t_ns, sequence=seq)
        self._open_bytes += len(data)

    @property
    def chunk_open_bytes(self) -> int:
        return self._open_bytes

    def flush_chunk(self) -> None:
        self._w.flush()
        self._open_bytes = 0

    def tell(self) -> int:
        return self._f.tell() + self._open_bytes

    def chunk_summaries(self) -> List[ChunkSummary]:
        return []

    def close(self) -> None:
        if not self._f.closed:
            self._w.finish()
            self._f.close()

    def abort(self) -> None:
        self._f.close()
