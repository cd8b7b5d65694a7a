"""compressed_image_transport's codec: sensor_msgs/Image <-> sensor_msgs/CompressedImage."""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np

from minros.cv_bridge import CvBridge, CvBridgeError
from sensor_msgs.msg import CompressedImage, Image

__all__ = ["CompressionError", "encode", "decode"]

_bridge = CvBridge()
_COLOR = ("rgb8", "bgr8", "rgba8", "bgra8", "rgb16", "bgr16", "rgba16", "bgra16")
_MONO = ("mono8", "mono16", "8UC1", "16UC1")


class CompressionError(ValueError):
    """An image the transport cannot compress or a payload it cannot decode."""


def encode(msg: Any, fmt: str = "jpeg", jpeg_quality: int = 80, png_level: int = 9) -> Any:
    """``msg`` as a CompressedImage (``fmt`` 'jpeg' or 'png'), as compressed_image_transport
    writes it: JPEG takes 8-bit colour (sent as bgr8) and mono8; PNG also 16-bit."""
    encoding = msg.encoding
    color = encoding in _COLOR
    if not color and encoding not in _MONO:
        raise CompressionError(f"{fmt} compression of {encoding} images is not supported: "
                               "send bgr8, rgb8, mono8 (or 16-bit with png)")
    sixteen = "16" in encoding
    if fmt == "jpeg" and sixteen:
        raise CompressionError(f"jpeg compression needs 8-bit images, not {encoding}: use png")
    target = ("bgr16" if sixteen else "bgr8") if color else ("mono16" if sixteen else "mono8")
    try:
        image = _bridge.imgmsg_to_cv2(msg, target)
    except CvBridgeError as exc:
        raise CompressionError(str(exc)) from None
    if fmt == "jpeg":
        ok, data = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, int(jpeg_quality)])
    elif fmt == "png":
        ok, data = cv2.imencode(".png", image, [cv2.IMWRITE_PNG_COMPRESSION, int(png_level)])
    else:
        raise CompressionError(f"unknown compressed format '{fmt}' (jpeg or png)")
    if not ok:
        raise CompressionError(f"OpenCV could not {fmt}-encode a {encoding} image")
    out = CompressedImage(format=f"{encoding}; {fmt} compressed {target}", data=data.tobytes())
    out.header = msg.header
    return out


def decode(msg: Any) -> Any:
    """A CompressedImage as an Image, in the encoding its format names (before ';'); a bare
    format ('jpeg', 'png') gives bgr8 or mono8."""
    buffer = np.frombuffer(bytes(msg.data), dtype=np.uint8)
    image = cv2.imdecode(buffer, cv2.IMREAD_UNCHANGED) if buffer.size else None
    if image is None:
        raise CompressionError(f"could not decode a {len(buffer)}-byte '{msg.format}' image")
    channels = 1 if image.ndim == 2 else image.shape[2]
    decoded = ("bgr16" if image.dtype == np.uint16 else "bgr8") if channels == 3 else \
        ("mono16" if image.dtype == np.uint16 else "mono8") if channels == 1 else \
        ("bgra16" if image.dtype == np.uint16 else "bgra8")
    wanted = msg.format.split(";", 1)[0].strip() if ";" in msg.format else decoded
    try:
        out: Image = _bridge.cv2_to_imgmsg(image, decoded)
        if wanted != decoded:
            out = _bridge.cv2_to_imgmsg(_bridge.imgmsg_to_cv2(out, wanted), wanted)
    except CvBridgeError as exc:
        raise CompressionError(f"cannot turn a decoded {decoded} image into {wanted}: {exc}") \
            from None
    out.header = msg.header
    return out
