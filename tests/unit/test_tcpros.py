"""minros.wire.tcpros without sockets: header codec, framing, service responses, handshake checks."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from minros.wire import tcpros
from minros.wire.tcpros import FrameError, FrameReader, HeaderError

# -------------------------------------------------------------------- connection header


def test_header_encoding_is_byte_exact():
    data = tcpros.encode_header({"topic": "/chatter", "md5sum": "*"})
    # fields sorted by key, each uint32 length + key=value, total length first
    body = struct.pack("<I", 8) + b"md5sum=*" + struct.pack("<I", 14) + b"topic=/chatter"
    assert data == struct.pack("<I", len(body)) + body


def test_header_value_may_contain_equals_and_newlines():
    fields = {"message_definition": "string data\n# a=b\n", "x": "=="}
    data = tcpros.encode_header(fields)
    assert tcpros.decode_header(data[4:]) == fields


def test_header_rejects_bad_keys():
    with pytest.raises(HeaderError):
        tcpros.encode_header({"a=b": "c"})
    with pytest.raises(HeaderError):
        tcpros.encode_header({"": "c"})


@pytest.mark.parametrize("block, words", [
    (struct.pack("<I", 0), "empty field"),
    (struct.pack("<I", 10) + b"a=b", "overruns"),
    (struct.pack("<I", 3) + b"abc", "without '='"),
    (b"\x01\x00", "truncated"),
    (struct.pack("<I", 3) + b"a=\xff", "UTF-8"),
])
def test_header_decode_errors_name_the_problem(block, words):
    with pytest.raises(HeaderError, match=words):
        tcpros.decode_header(block)


def test_read_header_block_needs_more_then_parses():
    data = tcpros.encode_header({"callerid": "/n"})
    for cut in range(len(data)):
        assert tcpros.read_header_block(data[:cut]) is None
    fields, used = tcpros.read_header_block(data + b"rest")
    assert fields == {"callerid": "/n"} and used == len(data)


def test_read_header_block_refuses_oversize_before_reading_it():
    with pytest.raises(HeaderError, match="exceeds the limit"):
        tcpros.read_header_block(struct.pack("<I", 2_000_000), max_size=1 << 20)


def test_error_header_has_only_error_field():
    data = tcpros.encode_error_header("boom")
    assert tcpros.decode_header(data[4:]) == {"error": "boom"}


_keys = st.text(alphabet=st.characters(blacklist_characters="=", blacklist_categories=("Cs",)),
                min_size=1, max_size=12)
_values = st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=40)


@given(st.dictionaries(_keys, _values, max_size=8))
def test_header_round_trip(fields):
    data = tcpros.encode_header(fields)
    parsed, used = tcpros.read_header_block(data)
    assert parsed == fields and used == len(data)


@given(st.binary(max_size=200))
def test_header_garbage_never_crashes(data):
    try:
        tcpros.decode_header(data)
    except HeaderError:
        pass
    try:
        tcpros.read_header_block(data, max_size=150)
    except HeaderError:
        pass


# -------------------------------------------------------------------- handshake checks

PUBS = {"/chatter": ("std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1")}


def test_publisher_accepts_matching_and_wildcard():
    base = {"topic": "/chatter", "callerid": "/sub", "type": "std_msgs/String"}
    assert tcpros.publisher_header_error({**base, "md5sum": PUBS["/chatter"][1]}, "/pub", PUBS) is None
    assert tcpros.publisher_header_error({**base, "md5sum": "*"}, "/pub", PUBS) is None


@pytest.mark.parametrize("missing", ["topic", "md5sum", "callerid"])
def test_publisher_requires_fields(missing):
    header = {"topic": "/chatter", "md5sum": "*", "callerid": "/s"}
    del header[missing]
    assert tcpros.publisher_header_error(header, "/p", PUBS) == f"Missing required '{missing}' field"


def test_publisher_md5_mismatch_text_is_rospys():
    header = {"topic": "/chatter", "md5sum": "abc", "callerid": "/s", "type": "std_msgs/String"}
    assert tcpros.publisher_header_error(header, "/p", PUBS) == (
        "Client [/s] wants topic [/chatter] to have datatype/md5sum [std_msgs/String/abc], but our "
        "version has [std_msgs/String/992ce8a1687cec8c8bd883ec73ca41d1] Dropping connection.")
    header["type"] = "std_msgs/Int32"
    assert tcpros.publisher_header_error(header, "/p", PUBS) == (
        "topic types do not match: [std_msgs/Int32] vs. [std_msgs/String]")


def test_publisher_unknown_topic():
    header = {"topic": "/other", "md5sum": "*", "callerid": "/s"}
    error = tcpros.publisher_header_error(header, "/p", PUBS)
    assert error.startswith("[/p] is not a publisher of [/other]")


def test_subscriber_side_checks():
    assert tcpros.subscriber_header_error({"error": "x"}, "/t", "*", "*") == "remote error reported: x"
    assert "missing required field [type]" in tcpros.subscriber_header_error(
        {"md5sum": "a"}, "/t", "a", "p/T")
    assert "md5sum mismatch" in tcpros.subscriber_header_error(
        {"md5sum": "a", "type": "p/T"}, "/t", "b", "p/T")
    assert tcpros.subscriber_header_error({"md5sum": "a", "type": "p/T"}, "/t", "*", "*") is None


def test_service_header_checks():
    ok = {"service": "/add", "md5sum": "m", "callerid": "/c"}
    assert tcpros.service_header_error(ok, "/add", "m") is None
    assert tcpros.service_header_error({**ok, "md5sum": "*"}, "/add", "m") is None
    assert tcpros.service_header_error({**ok, "md5sum": "x"}, "/add", "m") == (
        "request from [/c]: md5sums do not match: [x] vs. [m]")
    assert tcpros.service_header_error({"service": "/add"}, "/add", "m") == "Missing required 'md5sum' field"


# -------------------------------------------------------------------- framing


def frames_of(*payloads: bytes) -> bytes:
    return b"".join(tcpros.encode_frame(p) for p in payloads)


def test_frames_in_one_chunk():
    reader = FrameReader()
    assert reader.feed(frames_of(b"a", b"", b"ccc")) == [b"a", b"", b"ccc"]
    assert reader.pending() == 0


def test_frames_byte_by_byte():
    data = frames_of(b"hello", b"world!")
    reader = FrameReader(buff_size=16)
    out = []
    for i in range(len(data)):
        out += reader.feed(data[i:i + 1])
    assert out == [b"hello", b"world!"]


def test_large_frame_gets_its_own_buffer_and_is_handed_over():
    big = bytes(range(256)) * 1000
    reader = FrameReader(buff_size=64)
    got = reader.feed(frames_of(b"x", big, b"y"))
    assert got == [b"x", big, b"y"]
    assert isinstance(got[1], bytearray)  # owned by the caller, not a view of a reused buffer


def test_large_frame_received_in_place():
    big = b"z" * 10_000
    reader = FrameReader(buff_size=64)
    data = frames_of(big)
    pos = 0
    got = []
    while pos < len(data):
        target = reader.recv_buffer()
        n = min(len(target), 999, len(data) - pos)
        target[:n] = data[pos:pos + n]
        got += reader.received_frames(n)
        pos += n
    assert got == [big] and reader.frames() == []


def test_oversize_frame_refused_before_allocation():
    reader = FrameReader(max_frame=1000)
    with pytest.raises(FrameError, match="exceeds the limit"):
        reader.feed(struct.pack("<I", 1001))


def test_lying_length_allocates_only_what_arrives():
    reader = FrameReader(max_frame=tcpros.DEFAULT_MAX_FRAME, buff_size=64)
    reader.feed(struct.pack("<I", 900_000_000) + b"abc")
    # the frame's own buffer starts at a bounded size, not at the announced 900 MB
    assert len(reader.recv_buffer()) <= 16 << 20
    with pytest.raises(FrameError, match="in the middle of a frame"):
        reader.eof()


def test_eof_between_frames_is_clean_and_mid_prefix_is_not():
    reader = FrameReader()
    reader.feed(frames_of(b"a"))
    reader.eof()
    reader.feed(b"\x05\x00")
    with pytest.raises(FrameError):
        reader.eof()


def test_service_response_framing():
    reader = FrameReader(ok_byte=True)
    data = tcpros.encode_service_response(b"\x01\x02") + tcpros.encode_service_error("bad")
    assert reader.feed(data) == [(True, b"\x01\x02"), (False, b"bad")]
    assert tcpros.encode_service_error("é")[:5] == b"\x00\x02\x00\x00\x00"


def test_service_response_bad_ok_byte():
    with pytest.raises(FrameError, match="ok byte"):
        FrameReader(ok_byte=True).feed(b"\x07\x00\x00\x00\x00")


def test_header_then_messages_with_changing_limit():
    reader = FrameReader(max_frame=tcpros.DEFAULT_MAX_HEADER)
    header = tcpros.encode_header({"md5sum": "*", "type": "*"})
    got = reader.feed(header + frames_of(b"m1"))
    assert tcpros.decode_header(got[0]) == {"md5sum": "*", "type": "*"}
    assert got[1:] == [b"m1"]
    reader.max_frame = 10
    with pytest.raises(FrameError):
        reader.feed(struct.pack("<I", 11))


@settings(max_examples=300)
@given(st.lists(st.binary(max_size=300), max_size=12), st.lists(st.integers(1, 97), min_size=1),
       st.integers(16, 128), st.booleans())
def test_framing_round_trip_any_chunking(payloads, cuts, buff_size, ok_byte):
    if ok_byte:
        data = b"".join(tcpros.encode_service_response(p) for p in payloads)
    else:
        data = frames_of(*payloads)
    reader = FrameReader(buff_size=buff_size, ok_byte=ok_byte)
    out: list = []
    pos = 0
    i = 0
    while pos < len(data):
        step = cuts[i % len(cuts)]
        i += 1
        out += reader.feed(data[pos:pos + step])
        pos += step
    reader.eof()
    expected = [(True, p) for p in payloads] if ok_byte else payloads
    assert [(ok, bytes(p)) for ok, p in out] == expected if ok_byte else [bytes(p) for p in out] == expected


@settings(max_examples=300)
@given(st.binary(max_size=400), st.integers(16, 64))
def test_framing_garbage_only_raises_frame_error(data, buff_size):
    reader = FrameReader(max_frame=500, buff_size=buff_size, ok_byte=bool(data[:1] == b"\x00"))
    try:
        reader.feed(data)
        reader.eof()
    except FrameError:
        pass


def test_good_frames_before_a_bad_one_are_delivered_first():
    reader = FrameReader(max_frame=100)
    data = frames_of(b"ok1", b"ok2") + struct.pack("<I", 101)
    target = reader.recv_buffer()
    target[:len(data)] = data
    # does not raise: the good frames come out first
    assert reader.received_frames(len(data)) == [b"ok1", b"ok2"]
    with pytest.raises(FrameError, match="exceeds the limit"):
        reader.frames()
    with pytest.raises(FrameError):
        reader.recv_buffer()


def _big_frames(reader: FrameReader, payloads: list) -> list:
    """Push each payload as one frame the way a subscriber does: the frames one received_frames
    call returns are used up before the next receive buffer is asked for."""
    got = []
    for payload in payloads:
        data = memoryview(struct.pack("<I", len(payload)) + payload)
        while len(data):
            target = reader.recv_buffer()
            n = min(len(target), len(data), 50_000)  # several receives per frame
            target[:n] = data[:n]
            data = data[n:]
            for frame in reader.received_frames(n):
                got.append((frame, bytes(frame)))  # what a copying consumer keeps
    return got


def test_reuse_big_receives_same_size_frames_into_one_buffer():
    reader = FrameReader(buff_size=4096, reuse_big=True)
    payloads = [bytes([i]) * 300_000 for i in range(3)] + [b"\x07" * 200_000]
    got = _big_frames(reader, payloads)
    assert [copy for _, copy in got] == payloads  # each copy was taken before the next frame
    frames = [frame for frame, _ in got]
    assert frames[0] is frames[1] is frames[2]  # same size: one bytearray
    assert frames[3] is not frames[0]  # another size: a buffer of its own


def test_big_frames_get_their_own_buffer_by_default_and_when_not_handed_out():
    reader = FrameReader(buff_size=4096)  # views into frames may live on (numpy_msg)
    frames = [frame for frame, _ in _big_frames(reader, [b"a" * 300_000, b"b" * 300_000])]
    assert frames[0] is not frames[1] and bytes(frames[0][:1]) == b"a"
    reader = FrameReader(buff_size=4096, reuse_big=True)
    size = 300_000
    both = b"".join(struct.pack("<I", size) + bytes([c]) * size for c in b"xy")
    first, second = reader.feed(both)  # both frames complete before either is handed out
    assert first is not second and bytes(first[:1]) == b"x" and bytes(second[:1]) == b"y"


def test_only_messages_that_copy_their_fields_let_a_subscriber_reuse_buffers():
    from minros.client.topics import AnyMsg
    from minros.msgs import numpy_msg
    from sensor_msgs.msg import Image

    assert Image._keeps_buffer is False
    assert numpy_msg(Image)._keeps_buffer is True
    assert getattr(AnyMsg, "_keeps_buffer", True) is True
