"""The MCAP storage file of a rosbag2 recording, written with one copy of each message.

rosbags' MCAP storage writer builds every message record in a BytesIO, copies it into the
chunk's BytesIO, copies the chunk out again and once more into the chunk record: four copies
of every image, and most of a conversion's time. This writer has rosbags' storage-writer
interface (``add_msgtype``, ``add_connection``, ``write``, ``close``, ``abort``) and the same
file layout as rosbag2's MCAP plugin: profile ``ros2``, schemas ``ros2msg``, channels
``cdr`` with the topic's ``offered_qos_profiles`` as metadata, messages in chunks (not
compressed) each followed by its message indexes, then a summary (schemas, channels,
statistics, chunk indexes, the ``rosbag2`` metadata record and its index, summary offsets) and
the footer. A message record goes straight to the file behind a record header; a chunk's
lengths and times are patched into its header when it is closed. CRCs are left 0 ("not
computed"), as rosbags writes them.

Record layouts: the MCAP specification (https://mcap.dev/spec), checked by reading the files
back with the ``mcap`` library and with rosbags (tests/unit/test_bag_ros2.py).
"""

from __future__ import annotations

import struct
from collections import defaultdict
from pathlib import Path
from typing import Any, BinaryIO, Dict, List, Tuple

MAGIC = b"\x89MCAP0\r\n"
OP_HEADER, OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE = 0x01, 0x02, 0x03, 0x04, 0x05
OP_CHUNK, OP_MESSAGE_INDEX, OP_CHUNK_INDEX, OP_STATISTICS = 0x06, 0x07, 0x08, 0x0B
OP_METADATA, OP_METADATA_INDEX, OP_SUMMARY_OFFSET, OP_DATA_END = 0x0C, 0x0D, 0x0E, 0x0F
#: a chunk is closed once it holds this many bytes (rosbags: 1 MiB; rosbag2: 768 KiB)
CHUNK_SIZE = 1 << 20

_OP_LEN = struct.Struct("<BQ")
#: a message record's header: op, record length, channel id, sequence, log time, publish time
_MESSAGE = struct.Struct("<BQHIQQ")
#: a chunk record up to its records: op, length, start, end, uncompressed size, crc,
#: compression "" (u32 length 0), records length
_CHUNK = struct.Struct("<BQQQQIIQ")
_U16, _U32, _U64 = struct.Struct("<H"), struct.Struct("<I"), struct.Struct("<Q")


def _string(text: str) -> bytes:
    data = text.encode("utf-8")
    return _U32.pack(len(data)) + data


def _map(items: Dict[str, str]) -> bytes:
    body = b"".join(_string(k) + _string(v) for k, v in sorted(items.items()))
    return _U32.pack(len(body)) + body


def _record(op: int, body: bytes) -> bytes:
    return _OP_LEN.pack(op, len(body)) + body


class McapStorageWriter:
    """``<dir>/<dir>.mcap`` of a rosbag2 recording (the name rosbags gives it)."""

    def __init__(self, path: Path, compression: Any = None) -> None:
        self.path = path / f"{path.name}.mcap"
        self.bio: BinaryIO = open(self.path, "xb")  # noqa: SIM115 - closed by close()/abort()
        from importlib.metadata import version

        self._write(MAGIC + _record(OP_HEADER, _string("ros2") + _string(
            f"minros (rosbags {version('rosbags')} layout)")))
        self.schemas: Dict[str, Tuple[int, bytes]] = {}  # type -> (id, record)
        self.channels: Dict[int, bytes] = {}  # id -> record
        self.schema_of: Dict[str, int] = {}
        self.counts: Dict[int, int] = defaultdict(int)
        self.start = 2**63 - 1
        self.end = 0
        self.chunk_indexes: List[bytes] = []
        self._chunk_start = -1  # file offset of the open chunk record
        self._chunk_used = 0  # bytes of records in it
        self._chunk_times = (2**63 - 1, 0)
        self._chunk_messages: Dict[int, List[Tuple[int, int]]] = defaultdict(list)

    def _write(self, data: Any) -> None:
        self.bio.write(data)

    # -- the storage-writer interface of rosbags ------------------------------------------------

    def add_msgtype(self, connection: Any) -> None:
        schema_id = len(self.schemas) + 1
        body = _U16.pack(schema_id) + _string(connection.msgtype) + _string("ros2msg") \
            + _U32.pack(len(connection.msgdef.data.encode())) + connection.msgdef.data.encode()
        record = _record(OP_SCHEMA, body)
        self.schemas[connection.msgtype] = (schema_id, record)
        self._close_chunk()
        self._write(record)

    def add_connection(self, connection: Any, offered_qos_profiles: str) -> None:
        schema_id = self.schemas[connection.msgtype][0]
        body = _U16.pack(connection.id) + _U16.pack(schema_id) + _string(connection.topic) \
            + _string(connection.ext.serialization_format) \
            + _map({"offered_qos_profiles": offered_qos_profiles})
        record = _record(OP_CHANNEL, body)
        self.channels[connection.id] = record
        self.counts[connection.id] += 0
        self._close_chunk()
        self._write(record)

    def write(self, connection: Any, timestamp: int, data: Any) -> None:
        if self._chunk_start < 0:
            self._chunk_start = self.bio.tell()
            self._write(bytes(_CHUNK.size))  # patched by _close_chunk
            self._chunk_used = 0
        cid = connection.id
        self._chunk_messages[cid].append((timestamp, self._chunk_used))
        size = len(data)
        self._write(_MESSAGE.pack(OP_MESSAGE, 22 + size, cid, 0, timestamp, timestamp))
        self._write(data)
        self._chunk_used += _MESSAGE.size + size
        self.counts[cid] += 1
        low, high = self._chunk_times
        if timestamp < low or timestamp > high:
            self._chunk_times = (min(low, timestamp), max(high, timestamp))
        if self._chunk_used >= CHUNK_SIZE:
            self._close_chunk()

    def _close_chunk(self) -> None:
        if self._chunk_start < 0:
            return
        start, end = self._chunk_times
        self.start, self.end = min(self.start, start), max(self.end, end)
        used = self._chunk_used
        header = _CHUNK.pack(OP_CHUNK, _CHUNK.size - 9 + used, start, end, used, 0, 0, used)
        after = self.bio.tell()
        self.bio.seek(self._chunk_start)
        self._write(header)
        self.bio.seek(after)
        # the message indexes, one per channel, then the chunk's entry in the summary
        offsets = []
        for cid, entries in sorted(self._chunk_messages.items()):
            offsets.append((cid, self.bio.tell()))
            pairs = b"".join(struct.pack("<QQ", t, off) for t, off in entries)
            self._write(_record(OP_MESSAGE_INDEX, _U16.pack(cid) + _U32.pack(len(pairs))
                                + pairs))
        index_end = self.bio.tell()
        offset_map = b"".join(struct.pack("<HQ", cid, off) for cid, off in offsets)
        self.chunk_indexes.append(_record(OP_CHUNK_INDEX, struct.pack(
            "<QQQQ", start, end, self._chunk_start, after - self._chunk_start)
            + _U32.pack(len(offset_map)) + offset_map
            + _U64.pack(index_end - after) + _string("")
            + struct.pack("<QQ", used, used)))
        self._chunk_start = -1
        self._chunk_times = (2**63 - 1, 0)
        self._chunk_messages = defaultdict(list)

    def close(self, version: int, metadata: str) -> None:
        """Close the last chunk, write the summary and the footer (``metadata``: the
        recording's metadata.yaml content, stored as rosbag2 stores it)."""
        self._close_chunk()
        meta = _record(OP_METADATA, _string("rosbag2")
                       + _map({"serialized_metadata": metadata}))
        meta_start = self.bio.tell()
        self._write(meta)
        self._write(_record(OP_DATA_END, _U32.pack(0)))
        summary_start = self.bio.tell()
        groups: List[Tuple[int, int, int]] = []

        def group(op: int, records: List[bytes]) -> None:
            if records:
                start = self.bio.tell()
                for r in records:
                    self._write(r)
                groups.append((op, start, self.bio.tell() - start))

        group(OP_SCHEMA, [r for _i, r in self.schemas.values()])
        group(OP_CHANNEL, list(self.channels.values()))
        counts = sorted(self.counts.items())
        count_map = b"".join(struct.pack("<HQ", cid, n) for cid, n in counts)
        total = sum(n for _c, n in counts)
        group(OP_STATISTICS, [_record(OP_STATISTICS, struct.pack(
            "<QHIIIIQQ", total, len(self.schemas), len(self.channels), 0, 1,
            len(self.chunk_indexes), self.start if total else 0, self.end if total else 0)
            + _U32.pack(len(count_map)) + count_map)])
        group(OP_CHUNK_INDEX, self.chunk_indexes)
        group(OP_METADATA_INDEX, [_record(OP_METADATA_INDEX, struct.pack(
            "<QQ", meta_start, len(meta)) + _string("rosbag2"))])
        offsets_start = self.bio.tell()
        for op, start, length in groups:
            self._write(_record(OP_SUMMARY_OFFSET, struct.pack("<BQQ", op, start, length)))
        self._write(_record(OP_FOOTER, struct.pack("<QQI", summary_start, offsets_start, 0)))
        self._write(MAGIC)
        self.bio.close()

    def abort(self) -> None:
        self.bio.close()
