"""image_transport's raw and compressed transports, and ``republish`` between them.

``compressed`` is compressed_image_transport's codec: JPEG or PNG through OpenCV, with its
``format`` strings (``"bgr8; jpeg compressed bgr8"``), so ROS subscribers decode what minros
sends and minros decodes what ROS sends (also cv_bridge's bare ``"jpeg"``). The program is
``rosrun image_transport republish raw in:=/cam/image compressed out:=/cam/repub``.
Theora and compressedDepth are not there.
"""

from minros.image_transport.compressed import CompressionError, decode, encode

__all__ = ["encode", "decode", "CompressionError"]
