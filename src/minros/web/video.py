"""The video endpoints, as web_video_server serves them: MJPEG streams, snapshots, a viewer page.

``/stream?topic=T`` answers ``multipart/x-mixed-replace`` JPEG parts (``&width=&height=`` resize,
at most to the source's size or 3840 x 2160 pixels, whichever is larger,
``&quality=`` 1-100, default 95, ``&invert`` rotates 180 degrees, ``&type=mjpeg`` or
``ros_compressed``), ``/snapshot?topic=T`` one JPEG, ``/stream_viewer?topic=T`` a page showing the
stream, and ``/`` lists image topics when asked for ``?list``. ``sensor_msgs/Image`` in every
cv_bridge encoding and ``sensor_msgs/CompressedImage`` are shown.

One :class:`ImageFeed` per topic holds the latest frame; a JPEG is encoded at most once per frame
for each set of stream parameters, by the first viewer that wants it, and shared with every
other viewer with the same parameters. A viewer slower than the topic skips frames. This module
has no sockets: the server writes what it returns.
"""

from __future__ import annotations

import html
import threading
import urllib.parse
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

IMAGE = "sensor_msgs/Image"
COMPRESSED = "sensor_msgs/CompressedImage"
BOUNDARY = "boundarydonotcross"
DEFAULT_QUALITY = 95
MAX_SIDE = 16384
#: frames are sent at most this large (4K UHD) unless the source is larger (see output_size)
MAX_OUTPUT_PIXELS = 3840 * 2160
#: JPEGs of the latest frame kept per feed, one per parameter set (the oldest set goes first)
MAX_PARAM_SETS = 16


class VideoError(ValueError):
    """A request the video endpoints cannot serve; ``status`` is the HTTP status."""

    def __init__(self, text: str, status: int = 400) -> None:
        super().__init__(text)
        self.status = status


@dataclass(frozen=True)
class StreamParams:
    topic: str
    width: int = -1
    height: int = -1
    quality: int = DEFAULT_QUALITY
    invert: bool = False
    type: str = "mjpeg"

    @property
    def key(self) -> Tuple[int, int, int, bool]:
        return (self.width, self.height, self.quality, self.invert)


def _int(query: Dict[str, List[str]], name: str, default: int, low: int, high: int) -> int:
    values = query.get(name)
    if not values or values[0] == "":
        return default
    try:
        value = int(values[0])
    except ValueError:
        raise VideoError(f"{name}={values[0]!r} is not an integer") from None
    if value != default and not low <= value <= high:
        raise VideoError(f"{name}={value} is out of range ({low}..{high})")
    return value


def parse_params(query_string: str) -> StreamParams:
    """The stream parameters of a query string (web_video_server's names and defaults)."""
    query = urllib.parse.parse_qs(query_string, keep_blank_values=True)
    topic = (query.get("topic") or [""])[0]
    if not topic:
        raise VideoError("missing ?topic=: name the image topic, e.g. /stream?topic=/camera/image_raw")
    if not topic.startswith("/"):
        topic = "/" + topic
    kind = (query.get("type") or ["mjpeg"])[0]
    if kind not in ("mjpeg", "ros_compressed"):
        raise VideoError(f"type={kind!r} is not served here: use type=mjpeg or ros_compressed", 404)
    return StreamParams(topic=topic, width=_int(query, "width", -1, 1, MAX_SIDE),
                        height=_int(query, "height", -1, 1, MAX_SIDE),
                        quality=_int(query, "quality", DEFAULT_QUALITY, 1, 100),
                        invert="invert" in query, type=kind)


# -- pixels --------------------------------------------------------------------------------

def _scaled_to_8bit(image: np.ndarray) -> np.ndarray:
    """Float and deep integer images scaled so that their maximum is 255 (web_video_server's
    rule for float images; extended to 16/32-bit generic encodings)."""
    values = image.astype(np.float32)
    finite = values[np.isfinite(values)]
    top = float(finite.max()) if finite.size else 0.0
    if top > 0:
        values = values * (255.0 / top)
    return np.clip(np.nan_to_num(values), 0, 255).astype(np.uint8)


def _bgr(image: np.ndarray) -> np.ndarray:
    import cv2

    if image.ndim == 2:
        return cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
    channels = image.shape[2]
    if channels == 1:
        return cv2.cvtColor(image[:, :, 0], cv2.COLOR_GRAY2BGR)
    if channels == 2:
        return cv2.cvtColor(image[:, :, 0], cv2.COLOR_GRAY2BGR)
    if channels == 4:
        return cv2.cvtColor(image, cv2.COLOR_BGRA2BGR)
    return image


def image_to_bgr8(msg: Any) -> np.ndarray:
    """A displayable BGR8 image of a sensor_msgs/Image in any cv_bridge encoding."""
    from minros.cv_bridge import CvBridge, CvBridgeError

    bridge = CvBridge()
    encoding = msg.encoding
    try:
        image = bridge.imgmsg_to_cv2(msg, "passthrough")
    except CvBridgeError as exc:
        raise VideoError(f"cannot read the image: {exc}", 500) from None
    if "F" in encoding or image.dtype not in (np.uint8, np.int8) and not encoding.startswith(
            ("mono", "rgb", "bgr", "bayer")):
        return _bgr(_scaled_to_8bit(image))
    if encoding == "bgr8":
        return image
    try:
        return bridge.imgmsg_to_cv2(msg, "bgr8")
    except CvBridgeError:
        if image.dtype != np.uint8:
            image = _scaled_to_8bit(image)
        return _bgr(image)


def compressed_to_bgr8(msg: Any) -> np.ndarray:
    import cv2

    image = cv2.imdecode(np.frombuffer(msg.data, dtype=np.uint8), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise VideoError(f"cannot decode the {msg.format or 'compressed'} image", 500)
    if image.dtype != np.uint8:
        image = _scaled_to_8bit(image)
    return _bgr(image)


def output_size(width: int, height: int, params: StreamParams) -> Tuple[int, int]:
    """The size a frame of ``width`` x ``height`` is sent at: ``&width=``/``&height=`` as
    asked, shrunk (keeping their ratio) to at most the source's pixels or
    :data:`MAX_OUTPUT_PIXELS`, whichever is more: a viewer picks the size, and 16384 x 16384
    would take the server 800 MB per frame."""
    out_w = params.width if params.width > 0 else width
    out_h = params.height if params.height > 0 else height
    limit = max(width * height, MAX_OUTPUT_PIXELS)
    if out_w * out_h > limit:
        scale = (limit / (out_w * out_h)) ** 0.5
        out_w, out_h = max(1, int(out_w * scale)), max(1, int(out_h * scale))
    return out_w, out_h


def encode_jpeg(image: np.ndarray, params: StreamParams) -> bytes:
    import cv2

    height, width = image.shape[:2]
    out_w, out_h = output_size(width, height, params)
    if params.invert:
        image = cv2.flip(image, -1)
    if (out_w, out_h) != (width, height):
        image = cv2.resize(image, (out_w, out_h))
    ok, data = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, params.quality])
    if not ok:
        raise VideoError("OpenCV could not encode the frame as JPEG", 500)
    return data.tobytes()


def frame_jpeg(msg: Any, type_name: str, params: StreamParams) -> bytes:
    """The JPEG of one message for ``params``; a JPEG CompressedImage passes through untouched
    when no resize or rotation is asked for."""
    if type_name == COMPRESSED:
        if (("jpeg" in msg.format or "jpg" in msg.format) and params.width < 0
                and params.height < 0 and not params.invert):
            return bytes(msg.data)
        return encode_jpeg(compressed_to_bgr8(msg), params)
    if type_name != IMAGE:
        raise VideoError(f"{params.topic} is a {type_name}, not a sensor_msgs/Image or "
                         "CompressedImage", 415)
    return encode_jpeg(image_to_bgr8(msg), params)


def stamp_of(msg: Any) -> float:
    header = getattr(msg, "header", None)
    if header is None:
        return 0.0
    return header.stamp.secs + header.stamp.nsecs * 1e-9


# -- the feed of one topic -----------------------------------------------------------------

class ImageFeed:
    """The latest frame of an image topic and its JPEGs, shared by every viewer."""

    def __init__(self, topic: str) -> None:
        self.topic = topic
        self.cond = threading.Condition()
        self.seq = 0
        self.latest: Any = None  # minros.web.state.Incoming
        self.viewers = 0
        self._jpegs: Dict[Tuple[int, int, int, bool], Tuple[int, bytes, float]] = {}
        self._locks: Dict[Tuple[int, int, int, bool], threading.Lock] = {}
        self.encoded = 0  # JPEG encodings done (one per frame and parameter set at most)

    def push(self, incoming: Any) -> None:
        """A new frame arrived (the tap's thread: no decoding here)."""
        with self.cond:
            self.latest = incoming
            self.seq += 1
            self.cond.notify_all()

    def wait(self, after: int, timeout: float) -> int:
        """Block until a frame newer than ``after``; the newest sequence number (may equal
        ``after`` on timeout)."""
        with self.cond:
            self.cond.wait_for(lambda: self.seq > after, timeout)
            return self.seq

    def jpeg(self, params: StreamParams) -> Tuple[int, bytes, float]:
        """``(seq, jpeg, stamp)`` of the latest frame, encoded once for these parameters."""
        key = params.key
        with self.cond:
            lock = self._locks.get(key)
            if lock is None:
                if len(self._locks) >= MAX_PARAM_SETS:  # viewers pick the sizes: keep a few
                    oldest = next(iter(self._locks))
                    del self._locks[oldest]
                    self._jpegs.pop(oldest, None)
                lock = self._locks[key] = threading.Lock()
        with lock:
            with self.cond:
                seq, incoming = self.seq, self.latest
            cached = self._jpegs.get(key)
            if cached is not None and cached[0] == seq:
                return cached
            if incoming is None:
                raise VideoError(f"no frame received on {self.topic} yet", 503)
            msg = incoming.decoded()
            type_name = incoming.header.get("type", "")
            # kept in the feed (bounded), not on the message: a frame that stays the latest
            # (a latched image) would collect one JPEG per size every viewer asks for
            data = frame_jpeg(msg, type_name, params)
            result = (seq, data, stamp_of(msg))
            with self.cond:
                if key in self._locks:
                    self._jpegs[key] = result
            self.encoded += 1
            return result


# -- HTTP pieces ---------------------------------------------------------------------------

STREAM_HEADERS = [
    ("Connection", "close"), ("Server", "minros web"),
    ("Cache-Control", "no-cache, no-store, must-revalidate, pre-check=0, post-check=0, max-age=0"),
    ("Pragma", "no-cache"),
    ("Content-type", f"multipart/x-mixed-replace;boundary={BOUNDARY}"),
]


def stream_head(extra: Sequence[Tuple[str, str]] = ()) -> bytes:
    """The response head of an MJPEG stream (web_video_server's headers, without its
    ``Access-Control-Allow-Origin: *``: the server adds the origin of a page it trusts)."""
    lines = ["HTTP/1.1 200 OK"] + [f"{k}: {v}" for k, v in [*STREAM_HEADERS, *extra]]
    return ("\r\n".join(lines) + "\r\n\r\n" + f"--{BOUNDARY}\r\n").encode("ascii")


def stream_part(jpeg: bytes, stamp: float) -> List[bytes]:
    head = (f"Content-type: image/jpeg\r\nX-Timestamp: {stamp:.6f}\r\n"
            f"Content-Length: {len(jpeg)}\r\n\r\n").encode("ascii")
    return [head, jpeg, f"\r\n--{BOUNDARY}\r\n".encode("ascii")]


def snapshot_headers(stamp: float) -> List[Tuple[str, str]]:
    return [("Cache-Control", "no-cache, no-store, must-revalidate, "
            "pre-check=0, post-check=0, max-age=0"), ("X-Timestamp", f"{stamp:.6f}"),
            ("Pragma", "no-cache"), ("Content-Type", "image/jpeg")]


def viewer_page(params: StreamParams, query_string: str) -> str:
    topic = html.escape(params.topic)
    src = html.escape("/stream?" + query_string, quote=True)
    return (f"<html><head><title>{topic}</title></head><body><h1>{topic}</h1>"
            f'<img src="{src}"></img></body></html>')


def list_page(image_topics: List[str], token_query: str = "") -> str:
    items = []
    for topic in sorted(image_topics):
        q = urllib.parse.quote(topic, safe="/") + token_query
        t = html.escape(topic)
        items.append(f'<li><a href="/stream_viewer?topic={q}">{t}</a> '
                     f'(<a href="/stream?topic={q}">Stream</a>) '
                     f'(<a href="/snapshot?topic={q}">Snapshot</a>)</li>')
    return ("<html><head><title>ROS Image Topic List</title></head><body>"
            "<h1>Available ROS Image Topics:</h1><ul>" + "".join(items) + "</ul></body></html>")


def is_image_type(type_name: Optional[str]) -> bool:
    return type_name in (IMAGE, COMPRESSED)
