"""compressed_image_transport's codec: format strings, encodings kept, clear refusals."""

from __future__ import annotations

import numpy as np
import pytest

from minros.cv_bridge import CvBridge
from minros.image_transport import CompressionError, decode, encode
from sensor_msgs.msg import CompressedImage

bridge = CvBridge()


def _image(encoding: str, channels: int, dtype=np.uint8):
    shape = (8, 12, channels) if channels > 1 else (8, 12)
    data = (np.arange(np.prod(shape)) % 200).astype(dtype).reshape(shape)
    return bridge.cv2_to_imgmsg(data, encoding), data


@pytest.mark.parametrize("encoding, channels, fmt, expected", [
    ("bgr8", 3, "png", "bgr8; png compressed bgr8"),
    ("rgb8", 3, "png", "rgb8; png compressed bgr8"),
    ("mono8", 1, "png", "mono8; png compressed mono8"),
    ("mono8", 1, "jpeg", "mono8; jpeg compressed mono8"),
])
def test_round_trips_keep_the_encoding(encoding, channels, fmt, expected) -> None:
    msg, data = _image(encoding, channels)
    msg.header.frame_id = "cam"
    packed = encode(msg, fmt)
    assert packed.format == expected and packed.header.frame_id == "cam"
    back = decode(packed)
    assert back.encoding == encoding and back.header.frame_id == "cam"
    if fmt == "png":  # lossless
        assert np.array_equal(bridge.imgmsg_to_cv2(back), data)


def test_sixteen_bit_png_and_refusals() -> None:
    msg, data = _image("mono16", 1, np.uint16)
    back = decode(encode(msg, "png"))
    assert back.encoding == "mono16" and np.array_equal(bridge.imgmsg_to_cv2(back), data)
    with pytest.raises(CompressionError, match="jpeg compression needs 8-bit"):
        encode(msg, "jpeg")
    with pytest.raises(CompressionError, match="32FC1 images is not supported"):
        encode(bridge.cv2_to_imgmsg(np.zeros((2, 2), np.float32), "32FC1"))
    with pytest.raises(CompressionError, match="could not decode a 5-byte"):
        decode(CompressedImage(format="jpeg", data=b"nope!"))
