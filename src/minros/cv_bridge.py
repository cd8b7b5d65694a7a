"""CvBridge without the C++ extension: encodings table, numpy views and cv2 colour conversion.

``imgmsg_to_cv2`` with ``passthrough`` returns a numpy view onto the message's data (no copy),
as real cv_bridge does; a conversion to another encoding goes through ``cv2.cvtColor`` and,
between bit depths, a scaled ``convertTo`` the way cv_bridge's C++ core scales them.
"""

from __future__ import annotations

import mmap
import re
import sys
from typing import Any, Dict, Tuple

import numpy as np

_DEPTHS = {"8U": np.uint8, "8S": np.int8, "16U": np.uint16, "16S": np.int16,
           "32S": np.int32, "32F": np.float32, "64F": np.float64}
_DTYPE_TO_DEPTH = {np.dtype(v).name: k for k, v in _DEPTHS.items()}
# OpenCV's type codes: depth index + (channels - 1) * 8.
_DEPTH_CODES = {"8U": 0, "8S": 1, "16U": 2, "16S": 3, "32S": 4, "32F": 5, "64F": 6}
_CODE_DEPTHS = {v: k for k, v in _DEPTH_CODES.items()}

#: sensor_msgs/image_encodings.h: encoding -> (depth, channels)
_NAMED_ENCODINGS: Dict[str, Tuple[str, int]] = {
    "rgb8": ("8U", 3), "rgba8": ("8U", 4), "rgb16": ("16U", 3), "rgba16": ("16U", 4),
    "bgr8": ("8U", 3), "bgra8": ("8U", 4), "bgr16": ("16U", 3), "bgra16": ("16U", 4),
    "mono8": ("8U", 1), "mono16": ("16U", 1),
    "bayer_rggb8": ("8U", 1), "bayer_bggr8": ("8U", 1), "bayer_gbrg8": ("8U", 1),
    "bayer_grbg8": ("8U", 1), "bayer_rggb16": ("16U", 1), "bayer_bggr16": ("16U", 1),
    "bayer_gbrg16": ("16U", 1), "bayer_grbg16": ("16U", 1),
    "yuv422": ("8U", 2), "yuv422_yuy2": ("8U", 2),
}
_GENERIC = re.compile(r"^(8U|8S|16U|16S|32S|32F|64F)C([1-4])$")
# Colour layout of the named encodings, for cv2.cvtColor.
_LAYOUT = {"rgb8": "RGB", "rgb16": "RGB", "bgr8": "BGR", "bgr16": "BGR", "rgba8": "RGBA",
           "rgba16": "RGBA", "bgra8": "BGRA", "bgra16": "BGRA", "mono8": "GRAY", "mono16": "GRAY"}


class CvBridgeError(TypeError):
    """A conversion between a ROS image and an OpenCV image is not possible."""


def _depth_channels(encoding: str) -> Tuple[str, int]:
    if encoding in _NAMED_ENCODINGS:
        return _NAMED_ENCODINGS[encoding]
    match = _GENERIC.match(encoding)
    if match:
        return match.group(1), int(match.group(2))
    raise CvBridgeError(f"Unrecognized image encoding [{encoding}]")


def getCvType(encoding: str) -> int:  # noqa: N802 - cv_bridge's name
    """The OpenCV type code (e.g. CV_8UC3 == 16) of an image encoding."""
    depth, channels = _depth_channels(encoding)
    return _DEPTH_CODES[depth] + (channels - 1) * 8


class CvBridge:
    """Converts sensor_msgs/Image and CompressedImage messages to and from numpy images."""

    def __init__(self) -> None:
        self.cvtype_to_name: Dict[int, str] = {}
        for depth in _DEPTHS:
            for channels in (1, 2, 3, 4):
                name = f"{depth}C{channels}"
                self.cvtype_to_name[getCvType(name)] = name
        self.numpy_type_to_cvtype = dict(_DTYPE_TO_DEPTH)
        self.numpy_type_to_cvtype.update({v: k for k, v in _DTYPE_TO_DEPTH.items()})

    # -- type helpers (same names as cv_bridge) --
    def dtype_with_channels_to_cvtype2(self, dtype: Any, n_channels: int) -> str:
        try:
            return f"{_DTYPE_TO_DEPTH[np.dtype(dtype).name]}C{n_channels}"
        except KeyError:
            raise CvBridgeError(f"numpy type {np.dtype(dtype).name} has no OpenCV equivalent") from None

    def cvtype2_to_dtype_with_channels(self, cvtype: int) -> Tuple[str, int]:
        depth = _CODE_DEPTHS.get(cvtype & 7)
        if depth is None:
            raise CvBridgeError(f"unsupported OpenCV type {cvtype}")
        return np.dtype(_DEPTHS[depth]).name, (cvtype >> 3) + 1

    def encoding_to_cvtype2(self, encoding: str) -> int:
        return getCvType(encoding)

    def encoding_to_dtype_with_channels(self, encoding: str) -> Tuple[str, int]:
        depth, channels = _depth_channels(encoding)
        return np.dtype(_DEPTHS[depth]).name, channels

    # -- conversions --
    def imgmsg_to_cv2(self, img_msg: Any, desired_encoding: str = "passthrough") -> np.ndarray:
        """A numpy image of ``img_msg``; with ``passthrough`` a view onto the message data
        (a copy when that data is a shared-memory slot, valid only during a callback)."""
        dtype_name, channels = self.encoding_to_dtype_with_channels(img_msg.encoding)
        dtype = np.dtype(dtype_name).newbyteorder(">" if img_msg.is_bigendian else "<")
        height, width = int(img_msg.height), int(img_msg.width)
        data = img_msg.data
        if isinstance(data, str):
            data = data.encode("latin-1")
        row_bytes = width * channels * dtype.itemsize
        step = int(img_msg.step) or row_bytes
        needed = step * (height - 1) + row_bytes if height else 0
        if step < row_bytes or len(data) < needed:
            raise CvBridgeError(
                f"image data too short: {len(data)} bytes for {width}x{height} {img_msg.encoding} "
                f"with step {step}")
        shape = (height, width) if channels == 1 else (height, width, channels)
        strides = (step, channels * dtype.itemsize) if channels == 1 else (
            step, channels * dtype.itemsize, dtype.itemsize)
        image = np.ndarray(shape=shape, dtype=dtype, buffer=data, strides=strides)
        if isinstance(data, memoryview) and isinstance(data.obj, mmap.mmap):
            # a shared-memory slot (MINROSSHM), the publisher's again once the callback returns:
            # the image, often kept, gets pixels of its own
            image = image.copy()
        if dtype.byteorder not in ("=", "|") and (dtype.byteorder == ">") == (sys.byteorder == "little"):
            image = image.byteswap().view(dtype.newbyteorder("="))
        if desired_encoding == "passthrough" or desired_encoding == img_msg.encoding:
            return image
        return _convert(image, img_msg.encoding, desired_encoding)

    def cv2_to_imgmsg(self, cvim: np.ndarray, encoding: str = "passthrough",
                      header: Any = None) -> Any:
        """A sensor_msgs/Image holding a copy of ``cvim``'s pixels."""
        from sensor_msgs.msg import Image

        if not isinstance(cvim, (np.ndarray, np.generic)):
            raise TypeError("Your input type is not a numpy array")
        img_msg = Image()
        img_msg.height = int(cvim.shape[0])
        img_msg.width = int(cvim.shape[1])
        if header is not None:
            img_msg.header = header
        channels = 1 if cvim.ndim < 3 else int(cvim.shape[2])
        cv_type = self.dtype_with_channels_to_cvtype2(cvim.dtype, channels)
        if encoding == "passthrough":
            img_msg.encoding = cv_type
        else:
            img_msg.encoding = encoding
            if self.cvtype_to_name[self.encoding_to_cvtype2(encoding)] != cv_type:
                raise CvBridgeError(
                    f"encoding specified as {encoding}, but image has incompatible type {cv_type}")
        if cvim.dtype.byteorder == ">":
            img_msg.is_bigendian = True
        img_msg.data = np.ascontiguousarray(cvim).tobytes()
        img_msg.step = len(img_msg.data) // img_msg.height if img_msg.height else 0
        return img_msg

    def compressed_imgmsg_to_cv2(self, cmprs_img_msg: Any,
                                 desired_encoding: str = "passthrough") -> np.ndarray:
        """Decode a sensor_msgs/CompressedImage (jpeg, png, ...) into a numpy image."""
        import cv2

        buf = np.frombuffer(cmprs_img_msg.data, dtype=np.uint8)
        image = cv2.imdecode(buf, cv2.IMREAD_UNCHANGED)
        if image is None:
            raise CvBridgeError(f"could not decode the {cmprs_img_msg.format or 'compressed'} image")
        if desired_encoding == "passthrough":
            return image
        return _convert(image, "bgr8" if image.ndim == 3 else "mono8", desired_encoding)

    def cv2_to_compressed_imgmsg(self, cvim: np.ndarray, dst_format: str = "jpg") -> Any:
        """Encode ``cvim`` as a sensor_msgs/CompressedImage in ``dst_format`` (jpg, png, ...)."""
        import cv2

        from sensor_msgs.msg import CompressedImage

        if not isinstance(cvim, (np.ndarray, np.generic)):
            raise TypeError("Your input type is not a numpy array")
        msg = CompressedImage()
        msg.format = dst_format
        try:
            ok, encoded = cv2.imencode("." + dst_format, cvim)
        except cv2.error as exc:
            raise CvBridgeError(str(exc)) from None
        if not ok:
            raise CvBridgeError(f"OpenCV could not encode the image as {dst_format}")
        msg.data = encoded.tobytes()
        return msg


def _convert(image: np.ndarray, src: str, dst: str) -> np.ndarray:
    """Colour and depth conversion between two encodings, as cv_bridge's cvtColor2."""
    import cv2

    src_depth, _ = _depth_channels(src)
    dst_depth, dst_channels = _depth_channels(dst)
    out = image
    src_layout, dst_layout = _LAYOUT.get(src), _LAYOUT.get(dst)
    if src_layout and dst_layout and src_layout != dst_layout:
        code = getattr(cv2, f"COLOR_{src_layout}2{dst_layout}", None)
        if code is None:
            raise CvBridgeError(f"Unsupported conversion from [{src}] to [{dst}]")
        out = cv2.cvtColor(np.ascontiguousarray(out), code)
    elif (src_layout is None or dst_layout is None) and src != dst:
        generic_ok = _GENERIC.match(src) or _GENERIC.match(dst)
        channels = 1 if out.ndim == 2 else out.shape[2]
        if not generic_ok or channels != dst_channels:
            raise CvBridgeError(f"Unsupported conversion from [{src}] to [{dst}]")
    if src_depth != dst_depth:
        alpha = 1.0
        if src_depth == "8U" and dst_depth == "16U":
            alpha = 65535.0 / 255.0
        elif src_depth == "16U" and dst_depth == "8U":
            alpha = 255.0 / 65535.0
        out = (out.astype(np.float64) * alpha)
        info = np.iinfo(_DEPTHS[dst_depth]) if np.issubdtype(_DEPTHS[dst_depth], np.integer) else None
        if info is not None:
            out = np.clip(np.rint(out), info.min, info.max)
        out = out.astype(_DEPTHS[dst_depth])
    return out


__all__ = ["CvBridge", "CvBridgeError", "getCvType"]
