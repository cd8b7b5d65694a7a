"""CvBridge without the C++ extension: encodings table, numpy views and cv2 colour conversion.

``imgmsg_to_cv2`` with ``passthrough`` returns a numpy view onto the message's data (no copy),
as real cv_bridge does; a conversion to another encoding goes through ``cv2.cvtColor`` and,
between bit depths, a scaled ``convertTo`` the way cv_bridge's C++ core scales them.
"""

from __future__ import annotations

import functools
import mmap
import re
import sys
from typing import Any, Dict, Tuple

import numpy as np

_DEPTHS = {"8U": np.uint8, "8S": np.int8, "16U": np.uint16, "16S": np.int16,
           "32S": np.int32, "32F": np.float32, "64F": np.float64}
_DTYPE_TO_DEPTH = {np.dtype(v).name: k for k, v in _DEPTHS.items()}
# OpenCV's type codes: depth index + (channels - 1) << CV_CN_SHIFT, the shift the installed
# OpenCV uses (3 up to OpenCV 4, 5 from OpenCV 5, which has more depths): cv_bridge's codes are
# the cv2 module's (ROS's tests compare getCvType("32FC4") with cv2.CV_32FC4)
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
# cv_bridge's generic encodings: a depth with any number of channels (8UC5, 32FC10: OpenCV
# allows up to 512), or a bare depth, which is one channel (getCvType("8U") == CV_8UC1)
_GENERIC = re.compile(r"^(8U|8S|16U|16S|32S|32F|64F)(?:C([0-9]+))?$")
_MAX_CHANNELS = 512  # OpenCV's CV_CN_MAX
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
        channels = int(match.group(2) or 1)
        if not 1 <= channels <= _MAX_CHANNELS:
            raise CvBridgeError(f"image encoding [{encoding}]: OpenCV images have 1 to "
                                f"{_MAX_CHANNELS} channels")
        return match.group(1), channels
    raise CvBridgeError(f"Unrecognized image encoding [{encoding}]")


@functools.cache
def _cn_shift() -> int:
    """CV_CN_SHIFT of the installed OpenCV (CV_8UC2 is 1 << it); OpenCV 4's without one."""
    try:
        import cv2
    except ImportError:
        return 3
    return int(cv2.CV_8UC2).bit_length() - 1


def getCvType(encoding: str) -> int:  # noqa: N802 - cv_bridge's name
    """The OpenCV type code (cv2.CV_8UC3, ...) of an image encoding."""
    depth, channels = _depth_channels(encoding)
    return _DEPTH_CODES[depth] + ((channels - 1) << _cn_shift())


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
        depth = _CODE_DEPTHS.get(CV_MAT_DEPTHWrap(cvtype))
        if depth is None:
            raise CvBridgeError(f"unsupported OpenCV type {cvtype}")
        return np.dtype(_DEPTHS[depth]).name, CV_MAT_CNWrap(cvtype)

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
            if self.encoding_to_cvtype2(encoding) != getCvType(cv_type):
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


# ---------------------------------------------------------------------------------------------
# cv_bridge.boost.cv_bridge_boost: the functions of cv_bridge's C++ extension, in Python

class CvBridgeBoostError(RuntimeError):
    """A conversion the C++ cv_bridge refuses (its Python binding raises RuntimeError)."""


def CV_MAT_CNWrap(cvtype: int) -> int:  # noqa: N802 - cv_bridge_boost's name
    """The number of channels of an OpenCV type code."""
    return ((cvtype >> _cn_shift()) & 511) + 1


def CV_MAT_DEPTHWrap(cvtype: int) -> int:  # noqa: N802 - cv_bridge_boost's name
    """The depth code (0 = 8U ... 6 = 64F) of an OpenCV type code."""
    return cvtype & ((1 << _cn_shift()) - 1)


_COLOR = ("rgb8", "bgr8", "rgba8", "bgra8", "rgb16", "bgr16", "rgba16", "bgra16")
_MONO = ("mono8", "mono16")


def _is_color_format(encoding: str) -> bool:
    return encoding in _COLOR or encoding in _MONO or encoding.startswith("bayer_") or encoding == "yuv422"


def _bit_depth(encoding: str) -> int:
    depth, _channels = _depth_channels(encoding)
    return {"8U": 8, "8S": 8, "16U": 16, "16S": 16, "32S": 32, "32F": 32, "64F": 64}[depth]


def _check_conversion(src: str, dst: str) -> None:
    """cv_bridge's refusals (its getConversionCode), with its texts."""
    same_channels = _depth_channels(src)[1] == _depth_channels(dst)[1]
    if not _is_color_format(src):
        if _is_color_format(dst):
            raise CvBridgeBoostError(f"[{src}] is not a color format. but [{dst}] is. The conversion "
                                     "does not make sense")
        if not same_channels:
            raise CvBridgeBoostError(f"[{src}] and [{dst}] do not have the same number of channel")
    elif not _is_color_format(dst) and not same_channels:
        raise CvBridgeBoostError(f"[{src}] is a color format but [{dst}] is not so they must have "
                                 "the same OpenCV type, CV_8UC3, CV16UC1 ....")


def cvtColor2(image: np.ndarray, encoding_in: str, encoding_out: str) -> np.ndarray:  # noqa: N802
    """A copy of image converted from encoding_in to encoding_out (colour layout
    and bit depth, scaled between 8 and 16 bits)."""
    try:
        _check_conversion(encoding_in, encoding_out)
        if encoding_in == encoding_out:
            return np.array(image, copy=True)
        return _convert(np.asarray(image), encoding_in, encoding_out)
    except CvBridgeError as exc:
        raise CvBridgeBoostError(str(exc)) from None


#: the colours of label images (cv_bridge's rgb_colors: the CSS named colours in alphabetical
#: order without paleturquoise and rebeccapurple), as RGB hex; label n gets colour n % 146.
#: Two differ from CSS in cv_bridge's table, and so here: palevioletred (110) has
#: paleturquoise's value and sandybrown (123) is fa a4 60
_LABEL_COLORS = (
    "f0f8ff faebd7 00ffff 7fffd4 f0ffff f5f5dc ffe4c4 000000 ffebcd 0000ff 8a2be2 a52a2a "
    "deb887 5f9ea0 7fff00 d2691e ff7f50 6495ed fff8dc dc143c 00ffff 00008b 008b8b b8860b "
    "a9a9a9 006400 a9a9a9 bdb76b 8b008b 556b2f ff8c00 9932cc 8b0000 e9967a 8fbc8f 483d8b "
    "2f4f4f 2f4f4f 00ced1 9400d3 ff1493 00bfff 696969 696969 1e90ff b22222 fffaf0 228b22 "
    "ff00ff dcdcdc f8f8ff ffd700 daa520 808080 008000 adff2f 808080 f0fff0 ff69b4 cd5c5c "
    "4b0082 fffff0 f0e68c e6e6fa fff0f5 7cfc00 fffacd add8e6 f08080 e0ffff fafad2 d3d3d3 "
    "90ee90 d3d3d3 ffb6c1 ffa07a 20b2aa 87cefa 778899 778899 b0c4de ffffe0 00ff00 32cd32 "
    "faf0e6 ff00ff 800000 66cdaa 0000cd ba55d3 9370db 3cb371 7b68ee 00fa9a 48d1cc c71585 "
    "191970 f5fffa ffe4e1 ffe4b5 ffdead 000080 fdf5e6 808000 6b8e23 ffa500 ff4500 da70d6 "
    "eee8aa 98fb98 afeeee ffefd5 ffdab9 cd853f ffc0cb dda0dd b0e0e6 800080 ff0000 bc8f8f "
    "4169e1 8b4513 fa8072 faa460 2e8b57 fff5ee a0522d c0c0c0 87ceeb 6a5acd 708090 708090 "
    "fffafa 00ff7f 4682b4 d2b48c 008080 d8bfd8 ff6347 40e0d0 ee82ee f5deb3 ffffff f5f5f5 "
    "ffff00 9acd32 "
).split()


def _label_rgb(label: int) -> Tuple[float, float, float]:
    # cv_bridge keeps each colour's components to three significant digits
    hex_ = _LABEL_COLORS[label % len(_LABEL_COLORS)]
    return tuple(float(f"{int(hex_[i:i + 2], 16) / 255.0:.3g}") for i in (0, 2, 4))  # type: ignore[return-value]


def _labels_to_bgr(labels: np.ndarray, bg_label: int = -1) -> np.ndarray:
    table = np.array([[int(c * 255) for c in reversed(_label_rgb(i))]
                      for i in range(len(_LABEL_COLORS))], dtype=np.uint8)
    # C++'s % keeps the sign of the label: a negative label wraps to its own colour index
    index = np.fmod(labels.astype(np.int64), len(_LABEL_COLORS))
    out = table[np.where(index < 0, 0, index)]
    out[index < 0] = table[0] * 0  # C++ reads outside the table there: black is our answer
    out[labels == bg_label] = 0
    return out


def _saturate(values: np.ndarray, dtype: type) -> np.ndarray:
    info = np.iinfo(dtype)
    return np.clip(np.rint(np.nan_to_num(values, nan=0.0)), info.min, info.max).astype(dtype)


def cvtColorForDisplay(source: np.ndarray, encoding_in: str, encoding_out: str,  # noqa: N802
                       do_dynamic_scaling: bool = False, min_image_value: float = 0.0,
                       max_image_value: float = 0.0) -> np.ndarray:
    """An 8-bit image of source to show (cv_bridge's rules): label images (32SC1) in one
    colour per label, single-channel images scaled from [min, max] (their own with
    do_dynamic_scaling) to 0-255, anything else converted to encoding_out (bgr8
    when it is empty)."""
    image = np.asarray(source)
    encoding = encoding_out
    if not encoding:
        try:
            channels, depth = _depth_channels(encoding_in)[1], _bit_depth(encoding_in)
        except CvBridgeError:
            channels, depth = 0, 0
        if (channels == 1 and (encoding_in == "32SC1" or depth in (8, 16, 32))) or (
                channels > 1 and depth in (8, 16)):
            encoding = "bgr8"
        else:
            raise CvBridgeBoostError("cv_bridge.cvtColorForDisplay() output encoding is empty and "
                                     "cannot be guessed.")
    elif encoding not in _COLOR + _MONO or _bit_depth(encoding) != 8:
        raise CvBridgeBoostError("cv_bridge.cvtColorForDisplay() does not have an output encoding "
                                 "that is color or mono, and has is bit in depth")
    if encoding == "bgr8" and encoding_in == "32SC1":
        return _labels_to_bgr(image)
    low, high = float(min_image_value), float(max_image_value)
    if do_dynamic_scaling:
        low, high = float(np.nanmin(image)), float(np.nanmax(image))
        if low == high:
            return np.full(image.shape[:2] + (3,), 128, dtype=np.uint8)
    if low != high:
        if image.ndim == 3 and image.shape[2] != 1:
            raise CvBridgeBoostError("cv_bridge.cvtColorForDisplay() scaling for images with more "
                                     "than one channel is unsupported")
        shifted = image.astype(np.float64) - low
        if np.issubdtype(image.dtype, np.integer):  # OpenCV keeps the source type, saturated
            shifted = _saturate(shifted, image.dtype).astype(np.float64)
        scaled = _saturate(shifted * (255.0 / (high - low)), np.uint8)
        return cvtColor2(scaled, "mono8", encoding)
    # OpenCV type names taken as the colour layouts they most likely are
    typed = {"CV_8UC1": "mono8", "16UC1": "mono16", "CV_8UC3": "bgr8", "CV_8UC4": "bgra8",
             "CV_16UC3": "bgr16", "CV_16UC4": "bgra16"}.get(encoding_in, encoding_in)
    if typed == encoding:
        return image
    try:
        return cvtColor2(image, typed, encoding)
    except (CvBridgeBoostError, CvBridgeError) as exc:
        raise CvBridgeBoostError(f"cv_bridge.cvtColorForDisplay() while trying to convert image "
                                 f"from '{encoding_in}' to '{encoding}' an exception was thrown "
                                 f"({exc})") from None


__all__ = ["CvBridge", "CvBridgeError", "getCvType", "cvtColorForDisplay"]
