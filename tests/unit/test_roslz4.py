"""minros.roslz4: roslz4's streaming objects and its error."""

from __future__ import annotations

import pytest

import roslz4


def test_streaming_compressor_and_decompressor():
    data = b"minros " * 300000  # more than one 1 MB block
    compressor = roslz4.LZ4Compressor()
    frame = compressor.compress(data[:5]) + compressor.compress(data[5:]) + compressor.flush()
    assert frame[:4] == b"\x04\x22\x4d\x18"  # the LZ4 frame magic
    decompressor = roslz4.LZ4Decompressor()
    out = b"".join(decompressor.decompress(frame[i:i + 1000]) for i in range(0, len(frame), 1000))
    assert out == data == roslz4.decompress(roslz4.compress(data))


def test_malformed_input_is_one_oserror():
    with pytest.raises(OSError, match="malformed data to decompress"):
        roslz4.decompress(b"not an lz4 frame at all")
