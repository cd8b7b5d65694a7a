"""cv_bridge stand-in: encodings, zero-copy views, conversions, and agreement with Debian's."""

from __future__ import annotations

import io
import json
import subprocess

import numpy as np
import pytest

from cv_bridge import CvBridge, CvBridgeError, getCvType
from sensor_msgs.msg import CompressedImage, Image
from support import REFERENCE_PYTHON, reference_env, require_reference

ENCODINGS = ["rgb8", "rgba8", "rgb16", "rgba16", "bgr8", "bgra8", "bgr16", "bgra16", "mono8",
             "mono16", "bayer_rggb8", "bayer_grbg16", "yuv422", "8UC1", "8UC3", "16SC2", "32FC1",
             "64FC4", "32SC3", "8SC4"]


def _roundtrip(msg: Image) -> Image:
    buff = io.BytesIO()
    msg.serialize(buff)
    return Image().deserialize(buff.getvalue())


def test_passthrough_is_a_view_onto_the_message_data():
    bridge = CvBridge()
    image = np.random.default_rng(1).integers(0, 255, (48, 64, 3), dtype=np.uint8)
    msg = _roundtrip(bridge.cv2_to_imgmsg(image, "bgr8"))
    assert (msg.encoding, msg.height, msg.width, msg.step) == ("bgr8", 48, 64, 192)
    view = bridge.imgmsg_to_cv2(msg)
    assert np.array_equal(view, image)
    assert np.shares_memory(view, np.frombuffer(msg.data, dtype=np.uint8))


def test_passthrough_encoding_names_the_opencv_type():
    bridge = CvBridge()
    assert bridge.cv2_to_imgmsg(np.zeros((2, 2, 3), np.uint8)).encoding == "8UC3"
    assert bridge.cv2_to_imgmsg(np.zeros((2, 2), np.float32)).encoding == "32FC1"


def test_colour_and_depth_conversions():
    bridge = CvBridge()
    bgr = np.zeros((2, 2, 3), np.uint8)
    bgr[..., 0] = 255  # blue
    msg = bridge.cv2_to_imgmsg(bgr, "bgr8")
    assert bridge.imgmsg_to_cv2(msg, "rgb8")[0, 0].tolist() == [0, 0, 255]
    assert bridge.imgmsg_to_cv2(msg, "mono8").shape == (2, 2)
    as16 = bridge.imgmsg_to_cv2(msg, "bgr16")
    assert as16.dtype == np.uint16 and as16[0, 0, 0] == 65535


def test_bad_input_raises_cvbridgeerror():
    bridge = CvBridge()
    with pytest.raises(CvBridgeError, match="incompatible type"):
        bridge.cv2_to_imgmsg(np.zeros((2, 2), np.uint8), "bgr8")
    with pytest.raises(CvBridgeError, match="Unrecognized image encoding"):
        bridge.imgmsg_to_cv2(Image(height=1, width=1, encoding="nonsense", data=b"\0"))
    with pytest.raises(CvBridgeError, match="too short"):
        bridge.imgmsg_to_cv2(Image(height=4, width=4, encoding="bgr8", step=12, data=b"\0" * 10))
    with pytest.raises(TypeError):
        bridge.cv2_to_imgmsg([[1, 2], [3, 4]])


def test_compressed_roundtrip():
    bridge = CvBridge()
    image = np.full((16, 16, 3), 200, np.uint8)
    msg = bridge.cv2_to_compressed_imgmsg(image, "png")
    assert isinstance(msg, CompressedImage) and msg.format == "png"
    assert np.array_equal(bridge.compressed_imgmsg_to_cv2(msg), image)


@pytest.mark.slow
def test_matches_debians_cv_bridge():
    """getCvType and cv2_to_imgmsg fields agree with Debian's python3-cv-bridge."""
    require_reference()
    script = (
        "import json, numpy as np\n"
        "from cv_bridge import CvBridge\n"
        "from cv_bridge.boost.cv_bridge_boost import getCvType\n"
        f"encs = {ENCODINGS!r}\n"
        "im = (np.arange(5*7*3) % 251).astype(np.uint8).reshape(5, 7, 3)\n"
        "m = CvBridge().cv2_to_imgmsg(im, 'bgr8')\n"
        "import cv2\n"
        "shift = cv2.CV_8UC2.bit_length() - 1\n"
        "print(json.dumps({'types': [getCvType(e) for e in encs], 'shift': shift, "
        "'msg': [m.height, m.width, "
        "m.encoding, m.is_bigendian, m.step, m.data.hex()], "
        "'rgb': CvBridge().imgmsg_to_cv2(m, 'rgb8').tobytes().hex()}))\n"
    )
    out = subprocess.run([REFERENCE_PYTHON, "-c", script], env=reference_env({}),
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    ref = json.loads(out.stdout)
    import cv2

    def decoded(types: list, shift: int) -> list:  # (depth, channels): the same in any OpenCV
        return [(t & ((1 << shift) - 1), (t >> shift) + 1) for t in types]

    ours = cv2.CV_8UC2.bit_length() - 1
    assert decoded([getCvType(e) for e in ENCODINGS], ours) == decoded(ref["types"], ref["shift"])
    image = (np.arange(5 * 7 * 3) % 251).astype(np.uint8).reshape(5, 7, 3)
    bridge = CvBridge()
    msg = bridge.cv2_to_imgmsg(image, "bgr8")
    assert [msg.height, msg.width, msg.encoding, msg.is_bigendian, msg.step,
            msg.data.hex()] == ref["msg"]
    assert bridge.imgmsg_to_cv2(msg, "rgb8").tobytes().hex() == ref["rgb"]


# the same calls through Debian's C++ extension and minros's Python: each prints the result
# (dtype, shape, bytes) or the error's type and text
DISPLAY_CASES = r'''
import json, sys
import numpy as np
from cv_bridge.boost.cv_bridge_boost import (CV_MAT_CNWrap, CV_MAT_DEPTHWrap, cvtColor2,
                                             cvtColorForDisplay)
rng = np.random.default_rng(7)
depth16 = rng.integers(0, 5000, (4, 6), dtype=np.uint16)
depth32 = rng.uniform(0.5, 4.0, (4, 6)).astype(np.float32)
depth32[1, 2] = np.nan
colour = rng.integers(0, 255, (4, 6, 3), dtype=np.uint8)
labels = np.arange(-3, 300, dtype=np.int32).reshape(3, 101)
calls = [
    (cvtColorForDisplay, (labels, "32SC1", "")),
    (cvtColorForDisplay, (labels, "32SC1", "bgr8")),
    (cvtColorForDisplay, (depth16, "16UC1", "", True)),
    (cvtColorForDisplay, (depth16, "mono16", "mono8", False, 1000.0, 3000.0)),
    (cvtColorForDisplay, (depth32, "32FC1", "bgr8", False, 0.5, 4.0)),
    (cvtColorForDisplay, (depth32, "32FC1", "bgr8")),
    (cvtColorForDisplay, (np.full((2, 2), 7, np.uint16), "mono16", "", True)),
    (cvtColorForDisplay, (colour, "rgb8", "")),
    (cvtColorForDisplay, (colour, "bgr8", "bgr8")),
    (cvtColorForDisplay, (colour, "CV_8UC3", "mono8")),
    (cvtColorForDisplay, (colour, "rgb8", "32FC1")),
    (cvtColorForDisplay, (colour, "bgr8", "mono8", False, 0.0, 10.0)),
    (cvtColorForDisplay, (depth32, "32FC3", "")),
    (cvtColor2, (colour, "rgb8", "mono8")),
    (cvtColor2, (depth16, "mono16", "mono8")),
    (cvtColor2, (depth32, "32FC1", "bgr8")),
    (cvtColor2, (colour, "bgr8", "8UC1")),
    (cvtColor2, (colour, "8UC3", "8UC1")),
    (cvtColor2, (colour, "8UC3", "16UC3")),
]
out = []
for fn, args in calls:
    try:
        r = fn(*args)
        out.append([str(r.dtype), list(r.shape), r.tobytes().hex()])
    except Exception as exc:
        out.append(["RuntimeError" if isinstance(exc, RuntimeError) else type(exc).__name__, str(exc)])
# type codes of each side's own OpenCV (OpenCV 5 shifts channels by 5 bits, 4 by 3)
import cv2
shift = cv2.CV_8UC2.bit_length() - 1
out.append([[CV_MAT_CNWrap(t), CV_MAT_DEPTHWrap(t)] for t in (
    depth + ((channels - 1) << shift)
    for depth, channels in ((0, 1), (0, 3), (5, 3), (3, 4), (6, 4), (0, 5)))])
print(json.dumps(out))
'''


@pytest.mark.slow
def test_display_conversion_matches_debians_extension():
    """cv_bridge.boost's cvtColorForDisplay (label colours, scaling, guessing the output) and
    cvtColor2 give Debian's C++ extension's pixels, and its refusals with its texts."""
    from support import PYTHON

    ours = subprocess.run([PYTHON, "-c", DISPLAY_CASES], capture_output=True, text=True,
                          timeout=60)
    assert ours.returncode == 0, ours.stderr
    mine = json.loads(ours.stdout)
    assert mine[0][:2] == ["uint8", [3, 101, 3]] and mine[10][0] == "RuntimeError"
    require_reference()
    out = subprocess.run([REFERENCE_PYTHON, "-c", DISPLAY_CASES], env=reference_env({}),
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    theirs = json.loads(out.stdout)
    for i, (a, b) in enumerate(zip(mine, theirs)):
        assert a == b, f"case {i}"


# cv_bridge's generic encodings (cv_bridge.cpp's getCvType: a depth with any number of
# channels, or a bare depth for one): ROS's own tests send 5-channel images and ask for "8U"

def test_generic_encodings_beyond_four_channels_and_bare_depths():
    import cv2

    from cv_bridge import CvBridge, CvBridgeError, getCvType

    assert getCvType("8U") == cv2.CV_8UC1
    assert getCvType("32F") == cv2.CV_32FC1
    assert getCvType("8UC5") == cv2.CV_8UC(5)
    assert getCvType("64FC10") == cv2.CV_64FC(10)
    for bad in ("8UC0", "8UC513", "8UCX", "9U"):
        with pytest.raises(CvBridgeError):
            getCvType(bad)
    bridge = CvBridge()
    assert bridge.encoding_to_dtype_with_channels("16SC7") == ("int16", 7)
    assert bridge.cvtype2_to_dtype_with_channels(cv2.CV_16SC(7)) == ("int16", 7)


@pytest.mark.parametrize("dtype", ["uint8", "int8", "uint16", "int16", "int32", "float32",
                                   "float64"])
def test_a_five_channel_image_round_trips(dtype):
    """As ROS's conversions.py test_encode_decode_cv2 does, channels 1 to 5."""
    from cv_bridge import CvBridge

    bridge = CvBridge()
    original = np.arange(6 * 4 * 5).astype(dtype).reshape(6, 4, 5)
    msg = bridge.cv2_to_imgmsg(original)
    assert msg.encoding == bridge.dtype_with_channels_to_cvtype2(np.dtype(dtype), 5)
    back = bridge.imgmsg_to_cv2(msg)
    assert back.dtype == original.dtype and back.shape == original.shape
    assert (back == original).all()
    # an explicit encoding of the same type is accepted, another one refused
    bridge.cv2_to_imgmsg(original, msg.encoding)
    from cv_bridge import CvBridgeError

    with pytest.raises(CvBridgeError):
        bridge.cv2_to_imgmsg(original, "rgb8")
