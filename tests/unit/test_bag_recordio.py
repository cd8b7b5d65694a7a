"""rosbag.bag's record-level helpers (minros.bag.recordio) and the Bag internals tools reach
for (_file, _file_header_pos): patching a bag record by record as ROS's tests do."""

from __future__ import annotations

import io
import os
import struct

import pytest

import rosbag
from rosbag import bag
from std_msgs.msg import Int32


def test_records_round_trip_with_ros_layout():
    f = io.BytesIO()
    bag._write_record(f, {"op": bag._pack_uint8(bag._OP_CONNECTION), "topic": "/a"}, b"xyz")
    raw = f.getvalue()
    entry1, entry2 = b"op=\x07", b"topic=/a"
    header = struct.pack("<L", len(entry1)) + entry1 + struct.pack("<L", len(entry2)) + entry2
    assert raw == struct.pack("<L", len(header)) + header + struct.pack("<L", 3) + b"xyz"
    f.seek(0)
    assert bag._peek_next_header_op(f) == bag._OP_CONNECTION and f.tell() == 0
    fields = bag._read_header(f, bag._OP_CONNECTION)
    assert bag._read_str_field(fields, "topic") == "/a"
    assert bag._read_record_data(f) == b"xyz"


def test_file_header_record_is_padded_to_4096_bytes():
    f = io.BytesIO()
    header = {"op": bag._pack_uint8(bag._OP_FILE_HEADER), "index_pos": bag._pack_uint64(0),
              "conn_count": bag._pack_uint32(0), "chunk_count": bag._pack_uint32(0)}
    bag._write_record(f, header, padded_size=bag._FILE_HEADER_LENGTH)
    assert len(f.getvalue()) == 8 + bag._FILE_HEADER_LENGTH


def test_errors_are_rosbags_with_its_texts():
    with pytest.raises(rosbag.ROSBagException, match="expecting 10 bytes, read 2"):
        bag._read_sized(io.BytesIO(struct.pack("<L", 10) + b"ab"))
    with pytest.raises(rosbag.ROSBagFormatException, match="error unpacking uint32"):
        bag._read_sized(io.BytesIO(b"\x01"))
    f = io.BytesIO()
    bag._write_record(f, {"op": bag._pack_uint8(bag._OP_CHUNK)})
    f.seek(0)
    with pytest.raises(rosbag.ROSBagFormatException, match="Expected op code: CONNECTION, got CHUNK"):
        bag._read_header(f, bag._OP_CONNECTION)
    with pytest.raises(rosbag.ROSBagFormatException, match='expected "conn" field in record'):
        bag._read_uint32_field({}, "conn")


def test_bag_exposes_its_file_and_file_header_position(tmp_path):
    fn = str(tmp_path / "a.bag")
    with rosbag.Bag(fn, "w") as b:
        b.write("/n", Int32(data=1))
        assert b._file_header_pos == 13 and b._file.writable()
    with rosbag.Bag(fn) as b:
        f, pos = b._file, b._file_header_pos
        f.seek(pos)
        fields = bag._read_header(f, bag._OP_FILE_HEADER)
        assert bag._read_uint32_field(fields, "conn_count") == 1
        padding = bag._read_record_data(f)
        assert len(padding) + len(bag._write_header(io.BytesIO(), fields)) == bag._FILE_HEADER_LENGTH


def test_every_record_of_a_written_bag_reads_back(tmp_path):
    """As test_bag.py's _read_all_records: records one after another to the end of the file."""
    fn = str(tmp_path / "b.bag")
    with rosbag.Bag(fn, "w", chunk_threshold=256) as b:
        for i in range(50):
            b.write("/n", Int32(data=i))
    ops = []
    with open(fn, "rb") as f:
        end = f.seek(0, os.SEEK_END)
        f.seek(13)
        while f.tell() < end:
            ops.append(bag._read_uint8_field(bag._read_header(f), "op"))
            bag._skip_sized(f)
    assert ops[0] == bag._OP_FILE_HEADER and bag._OP_CHUNK in ops and ops[-1] == bag._OP_CHUNK_INFO


def test_info_texts():
    assert bag._human_readable_size(2048) == "2.0 KB"
    assert bag._human_readable_frequency(1500.0) == "1.5 kHz"
    assert bag._median([3, 1, 2, 4]) == 2.5
