"""Stand-in for roslz4: LZ4 frames as ROS's roslz4 writes and reads them (minros.roslz4)."""

from minros.roslz4 import LZ4Compressor, LZ4Decompressor, compress, decompress  # noqa: F401
