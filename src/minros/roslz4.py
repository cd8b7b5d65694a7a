"""roslz4: LZ4 frames as ROS's roslz4 writes and reads them (bag chunks compressed 'lz4').

ROS's roslz4 is a C extension; here PyPI's lz4 does the compression (its frame API is the
LZ4 frame format roslz4 speaks). The frames are the ones roslz4 makes: independent 1 MB
blocks, a content checksum, no stored content size (roslz4 rejects frames with a content size
or block checksums as malformed). The streaming objects keep roslz4's names: a compressor's
``compress`` returns what is ready (the frame header first) and ``flush`` the rest; a
decompressor returns what it can decode of the data given so far. Malformed input raises
OSError("malformed data to decompress"), as roslz4 does.
"""

from __future__ import annotations

from typing import Any

__all__ = ["LZ4Compressor", "LZ4Decompressor", "compress", "decompress"]


def _frame_module() -> Any:
    import lz4.frame  # imported on first use: only bags compressed with lz4 need it

    return lz4.frame


class LZ4Compressor:
    """Compresses a stream into one LZ4 frame."""

    def __init__(self) -> None:
        frame = _frame_module()
        self._compressor = frame.LZ4FrameCompressor(
            block_size=frame.BLOCKSIZE_MAX1MB, block_linked=False, content_checksum=True,
            block_checksum=False, compression_level=0, auto_flush=False)
        self._header = self._compressor.begin()

    def compress(self, data: bytes) -> bytes:
        """The frame bytes ready after ``data`` (the header on the first call)."""
        out, self._header = self._header + self._compressor.compress(bytes(data)), b""
        return out

    def flush(self) -> bytes:
        """The rest of the frame: buffered blocks, the end mark and the checksum."""
        out, self._header = self._header + self._compressor.flush(), b""
        return out


class LZ4Decompressor:
    """Decompresses one LZ4 frame given in pieces."""

    def __init__(self) -> None:
        self._decompressor = _frame_module().LZ4FrameDecompressor()

    def decompress(self, data: bytes) -> bytes:
        try:
            return self._decompressor.decompress(bytes(data))
        except RuntimeError:
            raise OSError("malformed data to decompress") from None


def compress(data: bytes) -> bytes:
    """``data`` as one LZ4 frame."""
    compressor = LZ4Compressor()
    return compressor.compress(data) + compressor.flush()


def decompress(data: bytes) -> bytes:
    """The content of the LZ4 frame ``data``."""
    return LZ4Decompressor().decompress(data)
