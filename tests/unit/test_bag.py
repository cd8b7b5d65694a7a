"""minros.bag without processes: the Bag API over bag 2.0 and MCAP, reindexing, appending,
rosbag info's layout, and the recorder's pure parts (names, durations, queue, writer)."""

from __future__ import annotations

import io
import os
import struct
import threading
import time
from pathlib import Path

import pytest

import minros
from minros.bag import Bag, Compression, ROSBagException, ROSBagUnindexedException, bag1
from minros.bag.info import duration_str, human_frequency, human_size
from minros.bag.play import TimeTranslator, raw_class
from minros.bag.progress import ProgressMeter
from minros.bag.record import (
    FLUSH_INTERVAL,
    BagSink,
    RecordOptions,
    RecordQueue,
    bag_filename,
    parse_duration,
    topic_matches,
)
from std_msgs.msg import Int32, String


def _fill(path: Path, n: int = 100, compression: str = Compression.NONE, chunk: int = 2000) -> None:
    with Bag(str(path), "w", compression=compression, chunk_threshold=chunk) as b:
        for i in range(n):
            b.write("/s", String(f"m{i:03d}"), minros.Time(100 + i // 10, (i % 10) * 100_000_000))
            if i % 2 == 0:
                b.write("/i", Int32(i), minros.Time(100 + i // 10, (i % 10) * 100_000_000 + 1))


@pytest.mark.parametrize("name,compression", [("a.bag", "none"), ("b.bag", "lz4"), ("c.bag", "bz2"),
                                              ("d.mcap", "none"), ("e.mcap", "lz4")])
def test_round_trip(tmp_path, name, compression):
    path = tmp_path / name
    _fill(path, compression=compression)
    with Bag(str(path)) as b:
        assert b.get_message_count() == 150
        assert b.get_message_count("/i") == 50
        assert b.get_start_time() == 100.0 and b.get_end_time() == pytest.approx(109.900000001)
        info = b.get_type_and_topic_info()
        assert info.msg_types == {"std_msgs/Int32": Int32._md5sum, "std_msgs/String": String._md5sum}
        assert info.topics["/s"].message_count == 100 and info.topics["/s"].frequency == pytest.approx(10.0)
        msgs = list(b.read_messages(topics=["/s"], start_time=minros.Time(101), end_time=minros.Time(102)))
        assert [m.message.data for m in msgs] == [f"m{i:03d}" for i in range(10, 21)]  # inclusive
        assert type(msgs[0].message) is String and msgs[0].timestamp == minros.Time(101)
        everything = list(b.read_messages())
        assert [m.timestamp for m in everything] == sorted(m.timestamp for m in everything)
        raw = next(iter(b.read_messages("/i", raw=True, return_connection_header=True)))
        datatype, data, md5, _pos, cls = raw.message
        assert (datatype, data, md5, cls) == ("std_msgs/Int32", b"\0\0\0\0", Int32._md5sum, Int32)
        assert raw.connection_header["type"] == b"std_msgs/Int32"
        if name.endswith(".bag"):
            assert b.get_compression_info().compression == compression


def test_unknown_type_is_read_from_its_stored_definition(tmp_path):
    path = str(tmp_path / "x.bag")
    from minros.msgs import generate_dynamic

    cls = generate_dynamic("nobody/Thing", "float64 x\nstring[] names\n")["nobody/Thing"]
    with Bag(path, "w") as b:
        b.write("/thing", cls(x=2.5, names=["a", "b"]), minros.Time(5))
        with pytest.raises(ROSBagException, match="cannot locate message class"):
            b.write("/raw", ("nobody/Else", b"", "0" * 32, None), minros.Time(5), raw=True)
    with Bag(path) as b:
        (msg,) = [m.message for m in b.read_messages()]
    assert (msg._type, msg.x, msg.names) == ("nobody/Thing", 2.5, ["a", "b"])


def test_append_keeps_the_old_messages(tmp_path):
    path = tmp_path / "a.bag"
    _fill(path, n=20)
    with Bag(str(path), "a") as b:
        b.write("/s", String("late"), minros.Time(500))
        b.write("/new", Int32(7), minros.Time(501))
    with Bag(str(path)) as b:
        assert b.get_message_count() == 32
        assert [m.message.data for m in b.read_messages("/new")] == [7]
        assert b.get_end_time() == 501.0


def test_truncated_bag_is_unindexed_and_reindex_recovers_whole_chunks(tmp_path):
    path = tmp_path / "t.bag"
    _fill(path, n=300)
    size = path.stat().st_size
    os.truncate(path, size * 2 // 3)
    with pytest.raises(ROSBagUnindexedException):
        Bag(str(path))
    with Bag(str(path), allow_unindexed=True) as b:  # read through a scan of the chunks
        readable = b.get_message_count()
    assert readable > 150
    positions = []
    scan = bag1.reindex_in_place(str(path), positions.append)
    assert scan.stopped and positions == sorted(positions)
    with Bag(str(path)) as b:
        data = [m.message.data for m in b.read_messages("/s")]
        assert b.get_message_count() == readable
    assert len(data) >= 100
    assert data == [f"m{i:03d}" for i in range(len(data))]


def test_reindex_through_the_append_api_yields_chunk_offsets(tmp_path):
    path = tmp_path / "r.bag"
    _fill(path, n=50)
    raw = bytearray(path.read_bytes())
    at = raw.index(b"index_pos=") + len("index_pos=")
    raw[at:at + 8] = bytes(8)
    path.write_bytes(bytes(raw))
    b = Bag(str(path), "a", allow_unindexed=True)
    offsets = list(b.reindex())
    b.close()
    assert offsets and offsets[0] == bag1.DATA_START
    with Bag(str(path)) as b:
        assert b.get_message_count() == 75


def test_not_a_bag(tmp_path):
    path = tmp_path / "x.bag"
    path.write_text("not a bag\n")
    with pytest.raises(ROSBagException, match="This does not appear to be a bag file"):
        Bag(str(path))
    path.write_bytes(b"")
    with pytest.raises(ROSBagException, match="empty file"):
        Bag(str(path))


def test_info_layout(tmp_path, monkeypatch):
    monkeypatch.setenv("TZ", "UTC")
    time.tzset()
    path = tmp_path / "i.bag"
    _fill(path, n=20, chunk=10**6)
    with Bag(str(path), skip_index=True) as b:
        text = str(b)
        yaml_text = b._get_yaml_info()
        key = b._get_yaml_info("topics[0].messages")
    time.tzset()
    assert text == (
        f"path:        {path}\n"
        "version:     2.0\n"
        "duration:    1.9s\n"
        "start:       Jan 01 1970 00:01:40.00 (100.00)\n"
        "end:         Jan 01 1970 00:01:41.90 (101.90)\n"
        f"size:        {human_size(path.stat().st_size)}\n"
        "messages:    30\n"
        "compression: none [1/1 chunks]\n"
        "types:       std_msgs/Int32  [da5909fbe378aeaf85e547e830cc1bb7]\n"
        "             std_msgs/String [992ce8a1687cec8c8bd883ec73ca41d1]\n"
        "topics:      /i   10 msgs    : std_msgs/Int32 \n"
        "             /s   20 msgs    : std_msgs/String")
    assert "messages: 30\nindexed: True\ncompression: none\n" in yaml_text
    assert key == "10"


def test_human_units():
    assert human_size(1536) == "1.5 KB" and human_size(3 * 1024**3) == "3.0 GB"
    assert human_frequency(999.0) == "999.0 Hz" and human_frequency(1500) == "1.5 kHz"
    assert duration_str(59.94) == "59.9s" and duration_str(125) == "2:05s (125s)"
    assert duration_str(3725) == "1hr 2:05s (3725s)"


def test_progress_meter_draws_rosbags_bar():
    out = io.StringIO()
    meter = ProgressMeter("x.bag", 2048, out=out)
    meter.step(1024, force_update=True)
    meter.finish()
    text = out.getvalue()
    assert "x.bag" in text and " 50%" in text and "1.0 KB /   2.0 KB" in text
    assert text.endswith("100%              2.0 KB 00:00    \n")


# -- recorder pieces -----------------------------------------------------------------------

def test_bag_filenames():
    now = time.mktime((2026, 3, 4, 5, 6, 7, 0, 0, -1))
    assert bag_filename(None, "run", None) == "run.bag"
    assert bag_filename(None, "run.bag", 2) == "run_2.bag"
    assert bag_filename(None, "run.mcap", None) == "run.mcap"
    assert bag_filename("pre", None, None, now) == "pre_2026-03-04-05-06-07.bag"
    assert bag_filename(None, None, 0, now) == "2026-03-04-05-06-07_0.bag"


def test_parse_duration():
    assert parse_duration("30") == 30 and parse_duration("1.5m") == 90 and parse_duration("2h") == 7200
    # what ROS's recorder reads too: a unit after a space, "3.", ".5", exponents
    assert parse_duration("3s") == 3 and parse_duration("2 m") == 120
    assert parse_duration("3.") == 3 and parse_duration(".5m") == 30 and parse_duration("1e1") == 10
    for bad in ("", "x", "5d", "0", "-3", "3 ms"):
        with pytest.raises(ValueError):
            parse_duration(bad)


def test_topic_matches():
    import re

    pats = [re.compile("/cam.*")]
    assert topic_matches("/camera/image", pats, None)
    assert not topic_matches("/camera/image", pats, re.compile(".*image"))
    assert not topic_matches("/x/camera", pats, None)  # a whole-name match, as boost::regex_match


def test_queue_drops_oldest_and_counts_per_topic():
    q = RecordQueue(limit_bytes=100)
    for i in range(5):
        q.push(("/a" if i < 3 else "/b", i, b"x" * 40, {}))
    assert dict(q.drops) == {"/a": 3}
    assert [q.pop(0)[1], q.pop(0)[1]] == [3, 4]
    assert q.pop(0) is None and q.take_new_drops() == 3 and q.take_new_drops() == 0
    big = RecordQueue(limit_bytes=10)
    big.push(("/img", 0, b"y" * 50, {}))  # one message larger than the buffer still goes through
    assert big.pop(0)[1] == 0 and not big.drops


HEADER = {"type": "std_msgs/String", "md5sum": String._md5sum, "message_definition": "string data\n",
          "callerid": "/talker", "latching": "0"}


def _item(i: int, t: float) -> tuple:
    buff = io.BytesIO()
    String(f"m{i}").serialize(buff)
    return ("/chatter", int(t * 1e9), buff.getvalue(), HEADER)


def test_sink_hands_chunks_to_the_kernel_on_a_time_bound(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    logs = []
    sink = BagSink(RecordOptions(name="live"), lambda level, text: logs.append(text))
    sink.write(_item(0, 10.0))
    sink.maybe_flush(sink.chunk_started + FLUSH_INTERVAL / 2)
    assert bag1.scan_chunks(tmp_path / "live.bag.active").chunks == []
    sink.maybe_flush(sink.chunk_started + FLUSH_INTERVAL)
    # what a SIGKILL now would leave: a .bag.active whose chunks reindex finds
    scan = bag1.scan_chunks(tmp_path / "live.bag.active")
    assert [sum(c.counts.values()) for c in scan.chunks] == [1]
    sink.close_current()
    assert logs == ["Recording to 'live.bag'."]
    with Bag("live.bag") as b:
        (conn,) = b._connections.values()
        assert (conn.callerid, conn.latching) == ("/talker", "0")


def _messages(path: str) -> list:
    with Bag(path) as b:
        return [m.message.data for m in b.read_messages()]


def test_sink_splits_by_duration_and_keeps_max_splits(tmp_path, monkeypatch):
    """ROS's recorder: a split begins at every DURATION from the start of the recording, with
    the first message received *more* than DURATION after the period's start."""
    monkeypatch.chdir(tmp_path)
    sink = BagSink(RecordOptions(name="part", split=True, duration="1", max_splits=2),
                   lambda level, text: None)
    sink.start(100_000_000_000)
    for i in range(8):
        sink.write(_item(i, 100 + i * 0.5))  # 100.0, 100.5, ... 103.5
    sink.close_current()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part_2.bag", "part_3.bag"]
    assert _messages("part_2.bag") == ["m5", "m6"] and _messages("part_3.bag") == ["m7"]


def test_sink_duration_without_split_ends_the_recording(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    sink = BagSink(RecordOptions(name="short", duration="2"), lambda level, text: None)
    sink.start(100_000_000_000)
    times = [100.5, 101.5, 102.0, 102.1, 103.0]
    for i, t in enumerate(times):
        sink.write(_item(i, t))
        if sink.finished:
            break
    assert sink.finished and i == 3  # 102.0 is not more than 2 s after 100.0; 102.1 is
    sink.close_current()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["short.bag"]
    assert _messages("short.bag") == ["m0", "m1", "m2"]


def test_sink_size_without_split_ends_the_recording(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    sink = BagSink(RecordOptions(name="small", size_mb=1, chunksize_kb=64),
                   lambda level, text: None)
    big = String("x" * 300_000)
    buff = io.BytesIO()
    big.serialize(buff)
    written = 0
    while not sink.finished and written < 10:
        sink.write(("/big", 100_000_000_000 + written, buff.getvalue(), HEADER))
        written += 1
    assert sink.finished and written == 5  # 4 messages pass 1 MB; the 5th is not written
    sink.close_current()
    with Bag("small.bag") as b:
        assert b.get_message_count() == 4


def _run_sink(sink: BagSink, queue: RecordQueue, clock: list, ticks: list) -> threading.Thread:
    """The writer thread on a clock the test moves: each tick once the sink is idle."""
    writer = threading.Thread(target=sink.run, args=(queue,), daemon=True)
    writer.start()
    for t in ticks:
        time.sleep(FLUSH_INTERVAL)  # two idle looks of the writer per tick
        clock[0] = int(t * 1e9)
    return writer


def test_sink_duration_ends_an_idle_recording(tmp_path, monkeypatch):
    """No message at all: the recording still ends DURATION after it began (ROS's recorder
    looks at the clock every quarter second), leaving the empty bag it opened at the start."""
    monkeypatch.chdir(tmp_path)
    clock = [100_000_000_000]
    sink = BagSink(RecordOptions(name="idle", duration="1"), lambda level, text: None,
                   clock=lambda: clock[0])
    sink.start(clock[0])
    queue = RecordQueue(0)
    writer = _run_sink(sink, queue, clock, [100.5, 101.0])
    assert writer.is_alive()  # 1.0 s after the start is not more than the duration
    clock[0] = 101_000_000_001
    writer.join(5)
    assert not writer.is_alive() and sink.finished and not queue.closed
    assert sorted(p.name for p in tmp_path.iterdir()) == ["idle.bag"]
    assert _messages("idle.bag") == []


def test_sink_idle_split_by_duration_and_a_clock_leap(tmp_path, monkeypatch):
    """With --split an idle recording rotates files all the same (empty ones, as ROS's); a
    clock leaping a million periods ahead makes one new file, not a million."""
    monkeypatch.chdir(tmp_path)
    clock = [100_000_000_000]
    sink = BagSink(RecordOptions(name="part", split=True, duration="1"),
                   lambda level, text: None, clock=lambda: clock[0])
    sink.start(clock[0])
    queue = RecordQueue(0)
    writer = _run_sink(sink, queue, clock, [101.5, 1_000_100.5])
    wait = time.monotonic() + 5
    while sink.split_index != 2 and time.monotonic() < wait:
        time.sleep(0.05)
    queue.push(_item(0, 1_000_100.6))
    queue.close()
    writer.join(5)
    assert not writer.is_alive()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part_0.bag", "part_1.bag", "part_2.bag"]
    assert _messages("part_1.bag") == [] and _messages("part_2.bag") == ["m0"]
    assert sink.start_ns == 1_000_100_000_000_000  # the period that holds the leap's time


def test_raw_class_publishes_stored_bytes():
    from minros.bag.bag1 import ConnInfo

    cls = raw_class(ConnInfo(0, "/x", "nobody/Thing", "0123" * 8, "int8 a\n", None, "1"))
    buff = io.BytesIO()
    cls(b"\x07").serialize(buff)
    assert buff.getvalue() == b"\x07"
    assert (cls._type, cls._md5sum, cls._full_text, cls._has_header) == ("nobody/Thing", "0123" * 8, "int8 a\n", False)


def test_time_translator():
    tr = TimeTranslator(rate=2.0)
    tr.set(10_000_000_000, 50.0)
    assert tr.real(12_000_000_000) == 51.0
    tr.shift(0.25)
    assert tr.real(12_000_000_000) == 51.25


def _lz4_frame_blocks(frame: bytes) -> tuple:
    """(FLG byte, block-size id, [(stored uncompressed, block bytes)]) of one LZ4 frame."""
    assert frame[:4] == b"\x04\x22\x4d\x18"  # LZ4 frame magic
    flg, bd = frame[4], frame[5]
    pos = 7  # magic, FLG, BD, header checksum (no content size: checked by the caller)
    blocks = []
    while True:
        (size,) = struct.unpack_from("<I", frame, pos)
        pos += 4
        if size == 0:
            break
        n = size & 0x7FFFFFFF
        blocks.append((bool(size >> 31), frame[pos:pos + n]))
        pos += n
    assert len(frame) == pos + 4  # the content checksum ends the frame
    return flg, (bd >> 4) & 7, blocks


def test_lz4_chunks_are_frames_roslz4_reads(tmp_path):
    """roslz4 (ROS's LZ4 reader) accepts only frames of independent blocks, with a content
    checksum and without a content size; chunks over one block (every image bag) need it."""
    import lz4.block

    from sensor_msgs.msg import Image

    pattern = os.urandom(200_000)  # repeated: a linked block would refer to the one before
    img = Image(height=1, width=3 * len(pattern), encoding="mono8", step=3 * len(pattern),
                data=pattern * 3)
    path = tmp_path / "img.bag"
    with Bag(str(path), "w", compression="lz4", chunk_threshold=3 * 1024 * 1024) as b:
        for i in range(5):
            b.write("/img", img, minros.Time(1, i))
    raw = path.read_bytes()
    scan = bag1.scan_chunks(path)
    (chunk,) = scan.chunks
    datapos, size = scan.datapos[chunk.pos]
    flg, block_id, blocks = _lz4_frame_blocks(raw[datapos:datapos + size])
    assert flg >> 6 == 1 and flg & 0x20, "blocks must be independent (FLG bit 5)"
    assert not flg & 0x10 and not flg & 0x08 and flg & 0x04 and not flg & 0x01  # no block checksum,
    assert 4 <= block_id <= 7 and len(blocks) >= 3  # no content size, a content checksum
    # each block decodes on its own: nothing refers to the block before
    out = b"".join(data if stored else lz4.block.decompress(data, uncompressed_size=1 << (8 + 2 * block_id))
                   for stored, data in blocks)
    assert len(out) == chunk.uncompressed_size
    with Bag(str(path)) as b:
        assert [bytes(m.message.data) == img.data for m in b.read_messages()] == [True] * 5


def test_file_header_has_ros_layout(tmp_path):
    """ROS pads the file header's header and data to 4096 bytes (the record takes 4104); a ROS
    tool rewriting the header of a bag padded otherwise wrote into its first chunk."""
    path = tmp_path / "h.bag"
    _fill(path, n=20)
    raw = path.read_bytes()
    (hlen,) = struct.unpack_from("<I", raw, 13)
    (plen,) = struct.unpack_from("<I", raw, 17 + hlen)
    assert hlen + plen == 4096 and 13 + 8 + hlen + plen == bag1.DATA_START == 4117
    assert raw[4117 + 4:4117 + 12] == b"\x04\x00\x00\x00op=\x05"  # the first chunk starts there


def test_bags_of_the_old_layout_read_append_and_reindex(tmp_path):
    """Bags minros wrote with rosbags' file header (first record at 4109) keep working."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    path = tmp_path / "old.bag"
    store = get_typestore(Stores.ROS1_NOETIC)
    with Writer(path) as w:
        conn = w.add_connection("/i", "std_msgs/msg/Int32", typestore=store)
        for i in range(5):
            w.write(conn, i * 10**9, store.serialize_ros1(store.types["std_msgs/msg/Int32"](data=i),
                                                       "std_msgs/msg/Int32"))
    assert path.read_bytes()[4109 + 8:4109 + 12] == b"op=\x05"
    with Bag(str(path), "a") as b:
        b.write("/i", Int32(5), minros.Time(5))
    with Bag(str(path)) as b:
        assert [m.message.data for m in b.read_messages()] == list(range(6))
    os.truncate(path, path.stat().st_size - 30)  # into the index: reindex, keeping the layout
    bag1.reindex_in_place(str(path))
    assert path.read_bytes()[4109 + 8:4109 + 12] == b"op=\x05"
    with Bag(str(path)) as b:
        assert [m.message.data for m in b.read_messages()] == list(range(6))


def test_a_message_that_does_not_deserialize_raises_rosbag_and_genpy_kinds(tmp_path):
    from minros.bag.errors import ROSBagDeserializationException, ROSBagFormatException
    from minros.exceptions import DeserializationError

    path = tmp_path / "short.bag"
    with Bag(str(path), "w") as b:
        b.write("/i", Int32(1), minros.Time(1))
        b.write("/i", ("std_msgs/Int32", b"\x01\x02", Int32._md5sum, Int32), minros.Time(2), raw=True)
    with Bag(str(path)) as b:
        read = b.read_messages()
        assert next(read).message.data == 1
        with pytest.raises(ROSBagDeserializationException) as info:
            next(read)
    assert isinstance(info.value, ROSBagFormatException) and isinstance(info.value, DeserializationError)
    assert str(info.value).startswith("the std_msgs/Int32 message of /i at 2.000000000 does not "
                                      "deserialize (") and "\n" not in str(info.value)
    with Bag(str(path)) as b:  # raw reading hands the bytes over as they are
        assert [m.message[1] for m in b.read_messages(raw=True)] == [b"\x01\0\0\0", b"\x01\x02"]


def test_compression_may_change_between_chunks(tmp_path):
    """As in rosbag, setting ``compression`` closes the open chunk; later chunks use it."""
    path = tmp_path / "mixed.bag"
    with Bag(str(path), "w") as b:
        b.write("/i", Int32(1), minros.Time(1))
        b.compression = "lz4"
        b.write("/i", Int32(2), minros.Time(2))
        b.compression = "bz2"
        b.write("/i", Int32(3), minros.Time(3))
    with Bag(str(path)) as b:
        assert [c.compression for c in b._chunk_summaries()] == ["none", "lz4", "bz2"]
        assert [m.message.data for m in b.read_messages()] == [1, 2, 3]
