"""rosbag.bag's record-level helpers under ROS's names (``_write_record``, ``_read_sized``,
``_pack_uint32``, the ``_OP_*`` codes, ...): tools and tests written against rosbag read and
patch bag files record by record with them. Their errors are rosbag's (ROSBagException for a
short read, ROSBagFormatException for a malformed header) with rosbag's texts.

minros's own reading and writing is ``records.py``; these work on any binary file object.
"""

from __future__ import annotations

import os
import struct
import time
from typing import Any, BinaryIO, Callable, Dict, Mapping, Optional, Sequence, Union

from minros.msgs.tval import Time

from .errors import ROSBagException, ROSBagFormatException
from .records import FILE_HEADER_LENGTH, MAGIC

_VERSION = MAGIC.decode().rstrip("\n")
_FILE_HEADER_LENGTH = FILE_HEADER_LENGTH
_INDEX_VERSION = 1
_CHUNK_INDEX_VERSION = 1

_OP_MSG_DEF = 1
_OP_MSG_DATA = 2
_OP_FILE_HEADER = 3
_OP_INDEX_DATA = 4
_OP_CHUNK = 5
_OP_CHUNK_INFO = 6
_OP_CONNECTION = 7

_OP_CODES = {
    _OP_MSG_DEF: "MSG_DEF",
    _OP_MSG_DATA: "MSG_DATA",
    _OP_FILE_HEADER: "FILE_HEADER",
    _OP_INDEX_DATA: "INDEX_DATA",
    _OP_CHUNK: "CHUNK",
    _OP_CHUNK_INFO: "CHUNK_INFO",
    _OP_CONNECTION: "CONNECTION",
}

_U8, _U32, _U64, _TIME = struct.Struct("<B"), struct.Struct("<L"), struct.Struct("<Q"), struct.Struct("<LL")


def _pack_uint8(v: int) -> bytes:
    return _U8.pack(v)


def _pack_uint32(v: int) -> bytes:
    return _U32.pack(v)


def _pack_uint64(v: int) -> bytes:
    return _U64.pack(v)


def _pack_time(v: Any) -> bytes:
    return _TIME.pack(v.secs, v.nsecs)


def _unpack_uint8(v: bytes) -> int:
    return _U8.unpack(v)[0]


def _unpack_uint32(v: bytes) -> int:
    return _U32.unpack(v)[0]


def _unpack_uint64(v: bytes) -> int:
    return _U64.unpack(v)[0]


def _unpack_time(v: bytes) -> Time:
    return Time(*_TIME.unpack(v))


def _decode_str(v: Union[str, bytes]) -> str:
    return v if isinstance(v, str) else v.decode()


def _decode_bytes(v: bytes) -> bytes:
    return v


# -- reading -------------------------------------------------------------------------------

def _read(f: BinaryIO, size: int) -> bytes:
    data = f.read(size)
    if len(data) != size:
        raise ROSBagException(f"expecting {size} bytes, read {len(data)}")
    return data


def _read_uint8(f: BinaryIO) -> int:
    return _unpack_uint8(f.read(1))


def _read_uint32(f: BinaryIO) -> int:
    return _unpack_uint32(f.read(4))


def _read_uint64(f: BinaryIO) -> int:
    return _unpack_uint64(f.read(8))


def _read_time(f: BinaryIO) -> Time:
    return _unpack_time(f.read(8))


def _read_sized(f: BinaryIO) -> bytes:
    """A uint32 length and that many bytes."""
    try:
        size = _read_uint32(f)
    except struct.error as exc:
        raise ROSBagFormatException(f"error unpacking uint32: {exc}") from None
    return _read(f, size)


def _skip_sized(f: BinaryIO) -> None:
    f.seek(_read_uint32(f), os.SEEK_CUR)


def _skip_record(f: BinaryIO) -> None:
    _skip_sized(f)  # the header
    _skip_sized(f)  # the data


def _build_header_from_str(header: bytes, req_op: Optional[int]) -> Dict[str, bytes]:
    """The fields of a record header (``name=value`` entries, each after its uint32 length);
    with ``req_op``, the record must have that op code."""
    fields: Dict[str, bytes] = {}
    view, pos = memoryview(header), 0
    while pos < len(view):
        if len(view) - pos < 4:
            raise ROSBagFormatException("Error reading header field")
        (size,) = _U32.unpack_from(view, pos)
        pos += 4
        if len(view) - pos < size:
            raise ROSBagFormatException("Error reading header field: expected "
                                        f"{size} bytes, read {len(view) - pos}")
        name, sep, value = bytes(view[pos:pos + size]).partition(b"=")
        if not sep:
            raise ROSBagFormatException("Error reading header field")
        fields[name.decode()] = value
        pos += size
    if req_op is not None:
        op = _read_uint8_field(fields, "op")
        if op != req_op:
            raise ROSBagFormatException(f"Expected op code: {_OP_CODES[req_op]}, got "
                                        f"{_OP_CODES.get(op, op)}")
    return fields


def _read_header(f: BinaryIO, req_op: Optional[int] = None) -> Dict[str, bytes]:
    try:
        header = _read_sized(f)
    except ROSBagException as exc:
        raise ROSBagFormatException(f"Error reading header: {exc}") from None
    return _build_header_from_str(header, req_op)


def _read_record_data(f: BinaryIO) -> bytes:
    try:
        return _read_sized(f)
    except ROSBagException as exc:
        raise ROSBagFormatException(f"Error reading record data: {exc}") from None


def _peek_next_header_op(f: BinaryIO) -> int:
    pos = f.tell()
    op = _read_uint8_field(_read_header(f), "op")
    f.seek(pos)
    return op


def _read_field(header: Mapping[str, bytes], field: str, unpack_fn: Callable[[bytes], Any]) -> Any:
    if field not in header:
        raise ROSBagFormatException(f'expected "{field}" field in record')
    try:
        return unpack_fn(header[field])
    except Exception as exc:
        raise ROSBagFormatException(f'error reading field "{field}": {exc}') from None


def _read_str_field(header: Mapping[str, bytes], field: str) -> str:
    return _read_field(header, field, _decode_str)


def _read_bytes_field(header: Mapping[str, bytes], field: str) -> bytes:
    return _read_field(header, field, _decode_bytes)


def _read_uint8_field(header: Mapping[str, bytes], field: str) -> int:
    return _read_field(header, field, _unpack_uint8)


def _read_uint32_field(header: Mapping[str, bytes], field: str) -> int:
    return _read_field(header, field, _unpack_uint32)


def _read_uint64_field(header: Mapping[str, bytes], field: str) -> int:
    return _read_field(header, field, _unpack_uint64)


def _read_time_field(header: Mapping[str, bytes], field: str) -> Time:
    return _read_field(header, field, _unpack_time)


# -- writing -------------------------------------------------------------------------------

def _as_bytes(v: Union[str, bytes]) -> bytes:
    return v if isinstance(v, bytes) else v.encode()


def _write_sized(f: BinaryIO, v: Union[str, bytes]) -> None:
    v = _as_bytes(v)
    f.write(_U32.pack(len(v)) + v)


def _write_header(f: BinaryIO, header: Mapping[Union[str, bytes], Union[str, bytes]]) -> bytes:
    """Write a record header from its fields (in the mapping's order); return its bytes."""
    parts = []
    for name, value in header.items():
        entry = _as_bytes(name) + b"=" + _as_bytes(value)
        parts.append(_U32.pack(len(entry)) + entry)
    header_bytes = b"".join(parts)
    _write_sized(f, header_bytes)
    return header_bytes


def _write_record(f: BinaryIO, header: Mapping[Union[str, bytes], Union[str, bytes]],
                  data: Union[str, bytes] = "", padded_size: Optional[int] = None) -> None:
    """A header and its data; with ``padded_size``, the data is spaces that make the header and
    data that long (the file header record is always 4096 bytes)."""
    header_bytes = _write_header(f, header)
    if padded_size is not None:
        data = b" " * max(padded_size - len(header_bytes), 0)
    _write_sized(f, data)


# -- the texts of rosbag info --------------------------------------------------------------

def _human_readable_size(size: float) -> str:
    for suffix in ("KB", "MB", "GB", "TB", "PB", "EB", "ZB", "YB"):
        size /= 1024.0
        if size < 1024.0:
            return f"{size:.1f} {suffix}"
    return "-"


def _human_readable_frequency(freq: float) -> str:
    for suffix in ("Hz", "kHz", "MHz", "GHz", "THz", "PHz", "EHz", "ZHz", "YHz"):
        if freq < 1000.0:
            return f"{freq:.1f} {suffix}"
        freq /= 1000.0
    return "-"


def _median(values: Sequence[float]) -> float:
    if not values:
        return float("nan")
    ordered, half = sorted(values), len(values) // 2
    if len(values) % 2:
        return ordered[half]
    return float(ordered[half - 1] + ordered[half]) / 2


def _time_to_str(secs: float) -> str:
    fraction = ("%.2f" % (secs - int(secs)))[1:]
    return time.strftime("%b %d %Y %H:%M:%S", time.localtime(secs)) + fraction


__all__ = [name for name in dir() if name.startswith("_") and not name.startswith("__")
           and name not in ("_U8", "_U32", "_U64", "_TIME", "_as_bytes")]
