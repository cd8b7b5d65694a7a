"""The records of bag format 2.0 that minros parses and writes itself.

rosbags writes the chunks and the messages in them; minros writes the version line, the file
header and the index (CONNECTION and CHUNK_INFO records after the chunks, INDEX_DATA records
after a chunk), because ROS lays out the file header differently from rosbags (see
:data:`FILE_HEADER_LENGTH`) and ``rosbag reindex`` must write an index for what it recovered.
The parser here is the one a damaged file meets: anything that does not parse raises
:class:`Damage`, with what was wrong, and allocates no more than the file holds.
"""

from __future__ import annotations

import re
import struct
from typing import BinaryIO, Dict, Iterable, List, Mapping, Optional, Tuple

from rosbags.interfaces import Connection, ConnectionExtRosbag1
from rosbags.typesys.msg import denormalize_msgtype

MAGIC = b"#ROSBAG V2.0\n"
#: ROS pads the file header record so that its header plus its data (the padding) are this
#: long (rosbag's ``_FILE_HEADER_LENGTH``, rosbag_storage's ``FILE_HEADER_LENGTH``): with the
#: two length fields the record takes 4104 bytes. rosbags pads the whole record to 4096, and a
#: ROS tool that rewrote the header of such a file (``rosbag reindex``, appending) wrote 8
#: bytes into its first chunk, so minros writes ROS's layout.
FILE_HEADER_LENGTH = 4096
#: where the first record after the file header starts, in ROS's layout
DATA_START = len(MAGIC) + 8 + FILE_HEADER_LENGTH
#: where it starts in bags minros wrote through rosbags' layout (read and rewritten as they are)
ROSBAGS_DATA_START = len(MAGIC) + FILE_HEADER_LENGTH

OP_MSGDATA = 2
OP_FILE_HEADER = 3
OP_IDXDATA = 4
OP_CHUNK = 5
OP_CHUNK_INFO = 6
OP_CONNECTION = 7

_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_TIME = struct.Struct("<II")
_INDEX_ENTRY = struct.Struct("<IIi")
#: the version line as ROS's rosbag matches it ("#ROS" anything " V" digit any digit)
_VERSION = re.compile(rb"#ROS(.*) V(\d).(\d)")


class Damage(Exception):
    """A record that does not parse: the file is damaged, or cut short, at this point."""


def read_version(f: BinaryIO) -> int:
    """The bag version from the version line (``#ROSBAG V2.0`` -> 200), ROS's way: the line
    is matched loosely, so one flipped letter in ``ROSBAG`` still reads. Raises ValueError
    with rosbag's wording for an empty file or one that is not a bag."""
    line = f.readline(64)
    if not line:
        raise ValueError("empty file")
    match = _VERSION.match(line)
    if match is None:
        raise ValueError("This does not appear to be a bag file")
    return int(match.group(2)) * 100 + int(match.group(3))


def parse_fields(buf: bytes, start: int, end: int) -> Dict[str, bytes]:
    """The ``name=value`` fields of the record header in ``buf[start:end]``."""
    fields: Dict[str, bytes] = {}
    pos = start
    while pos < end:
        if pos + 4 > end:
            raise Damage("a header field length is cut short")
        (size,) = _U32.unpack_from(buf, pos)
        pos += 4
        if pos + size > end:
            raise Damage("a header field overruns its header")
        name, sep, value = bytes(buf[pos:pos + size]).partition(b"=")
        if not sep:
            raise Damage("a header field has no '='")
        try:
            fields[name.decode()] = value
        except UnicodeDecodeError:
            raise Damage("a header field name is not text") from None
        pos += size
    return fields


def u8(fields: Mapping[str, bytes], name: str) -> int:
    value = fields.get(name)
    if value is None or len(value) != 1:
        raise Damage(f"no uint8 field {name!r}")
    return value[0]


def u32(fields: Mapping[str, bytes], name: str) -> int:
    value = fields.get(name)
    if value is None or len(value) != 4:
        raise Damage(f"no uint32 field {name!r}")
    return _U32.unpack(value)[0]


def u64(fields: Mapping[str, bytes], name: str) -> int:
    value = fields.get(name)
    if value is None or len(value) != 8:
        raise Damage(f"no uint64 field {name!r}")
    return _U64.unpack(value)[0]


def time_ns(fields: Mapping[str, bytes], name: str) -> int:
    value = fields.get(name)
    if value is None or len(value) != 8:
        raise Damage(f"no time field {name!r}")
    secs, nsecs = _TIME.unpack(value)
    return secs * 1_000_000_000 + nsecs


def text(fields: Mapping[str, bytes], name: str) -> str:
    value = fields.get(name)
    if value is None:
        raise Damage(f"no field {name!r}")
    try:
        return value.decode()
    except UnicodeDecodeError:
        raise Damage(f"field {name!r} is not text") from None


def read_record_header(f: BinaryIO, pos: int, end: int, cut_data: bool = False
                       ) -> Tuple[Dict[str, bytes], int, int]:
    """The record at ``pos`` of a file of ``end`` bytes: (header fields, data offset, data
    length). Every length is checked against the file before anything is read; with
    ``cut_data``, data that runs past the end is no error (the caller reads what is there)."""
    f.seek(pos)
    head = f.read(4)
    if len(head) < 4:
        raise Damage("the file ends inside a record")
    (hlen,) = _U32.unpack(head)
    if pos + 8 + hlen > end:
        raise Damage("a record header runs past the end of the file")
    buf = f.read(hlen + 4)
    fields = parse_fields(buf, 0, hlen)
    (dlen,) = _U32.unpack_from(buf, hlen)
    datapos = pos + 8 + hlen
    if datapos + dlen > end and not cut_data:
        raise Damage("a record's data runs past the end of the file")
    return fields, datapos, dlen


def read_index_entries(fields: Mapping[str, bytes], data: bytes) -> Tuple[int, List[Tuple[int, int]]]:
    """(connection id, [(time ns, offset in chunk)]) of an INDEX_DATA record."""
    if u32(fields, "ver") != 1:
        raise Damage("INDEX_DATA version is not 1")
    count = u32(fields, "count")
    if len(data) != count * _INDEX_ENTRY.size:
        raise Damage("INDEX_DATA length does not match its count")
    return u32(fields, "conn"), [(s * 1_000_000_000 + n, off)
                                 for s, n, off in _INDEX_ENTRY.iter_unpack(data)]


# -- writing ----------------------------------------------------------------------------------

def _header(fields: Iterable[Tuple[str, bytes]]) -> bytes:
    body = b"".join(_U32.pack(len(name) + 1 + len(value)) + name.encode() + b"=" + value
                    for name, value in fields)
    return _U32.pack(len(body)) + body


def _time(ns: int) -> bytes:
    return _TIME.pack(*divmod(ns, 1_000_000_000))


def record(fields: Iterable[Tuple[str, bytes]], data: bytes) -> bytes:
    return _header(fields) + _U32.pack(len(data)) + data


def file_header_record(index_pos: int, conn_count: int, chunk_count: int,
                       padded: int = FILE_HEADER_LENGTH) -> bytes:
    """The FILE_HEADER record, its header and padding ``padded`` bytes long together."""
    header = _header([("op", bytes([OP_FILE_HEADER])), ("index_pos", _U64.pack(index_pos)),
                      ("conn_count", _U32.pack(conn_count)), ("chunk_count", _U32.pack(chunk_count))])
    pad = max(padded - (len(header) - 4), 0)
    return header + _U32.pack(pad) + b" " * pad


def connection_record(conn: Connection) -> bytes:
    ext = conn.ext
    data = [("topic", conn.topic.encode()), ("type", denormalize_msgtype(conn.msgtype).encode()),
            ("md5sum", conn.digest.encode()), ("message_definition", conn.msgdef.data.encode())]
    if isinstance(ext, ConnectionExtRosbag1):
        if ext.callerid is not None:
            data.append(("callerid", ext.callerid.encode()))
        if ext.latching is not None:
            data.append(("latching", str(ext.latching).encode()))
    return _header([("op", bytes([OP_CONNECTION])), ("conn", _U32.pack(conn.id)),
                    ("topic", conn.topic.encode())]) + _header(data)


def chunk_header(compression: str, size: int, datasize: int) -> bytes:
    """The CHUNK record up to its data: ``size`` bytes uncompressed, ``datasize`` stored."""
    return _header([("op", bytes([OP_CHUNK])), ("compression", compression.encode()),
                    ("size", _U32.pack(size))]) + _U32.pack(datasize)


def index_data_records(entries: Mapping[int, List[Tuple[int, int]]]) -> bytes:
    """The INDEX_DATA records that follow a chunk: per connection, (time ns, offset) pairs."""
    out = []
    for cid, items in entries.items():
        data = b"".join(_time(t) + _U32.pack(offset) for t, offset in items)
        out.append(record([("op", bytes([OP_IDXDATA])), ("ver", _U32.pack(1)), ("conn", _U32.pack(cid)),
                           ("count", _U32.pack(len(items)))], data))
    return b"".join(out)


def chunk_info_record(pos: int, start: int, end: int, counts: Mapping[int, int]) -> bytes:
    data = b"".join(_U32.pack(cid) + _U32.pack(n) for cid, n in counts.items())
    return record([("op", bytes([OP_CHUNK_INFO])), ("ver", _U32.pack(1)), ("chunk_pos", _U64.pack(pos)),
                   ("start_time", _time(start)), ("end_time", _time(end)),
                   ("count", _U32.pack(len(counts)))], data)


ChunkIndex = Tuple[int, int, int, Mapping[int, int]]  # (pos, first ns, last ns, {conn: count})


def write_index(f: BinaryIO, connections: List[Connection], chunks: List[ChunkIndex],
                data_start: int = DATA_START) -> int:
    """Write the index where ``f`` stands (connections, then chunk infos), then the file
    header that points to it; ``data_start`` keeps the header's size as the file has it.
    Returns the index position."""
    index_pos = f.tell()
    f.write(b"".join(connection_record(c) for c in connections))
    f.write(b"".join(chunk_info_record(*c) for c in chunks))
    f.seek(0)
    f.write(MAGIC)
    f.write(file_header_record(index_pos, len(connections), len(chunks),
                               data_start - len(MAGIC) - 8))
    f.seek(0, 2)
    return index_pos


def data_start_of(f: BinaryIO, end: int) -> Optional[int]:
    """Where the first record after an intact file header starts (None when the header does
    not parse)."""
    try:
        fields, datapos, dlen = read_record_header(f, len(MAGIC), end)
        if u8(fields, "op") != OP_FILE_HEADER:
            return None
    except (Damage, OSError):
        return None
    return datapos + dlen
