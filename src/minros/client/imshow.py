"""``cv2.imshow`` for OpenCV builds without a GUI: windows become image topics for ``minros web``.

``opencv-python-headless`` (minros's default) raises "The function is not implemented" from
``cv2.imshow``, ``cv2.waitKey`` and the other window functions. When a node's OpenCV has no GUI
(its build information says ``GUI: NONE``) and ``MINROS_IMSHOW`` is not ``off``, :func:`install`
replaces them: ``cv2.imshow(name, image)`` publishes ``image`` as a ``sensor_msgs/Image`` on
``/imshow/<name>`` (8-bit BGR/gray/BGRA as imshow would show it: 16-bit images divided by 256,
float images times 255), which ``minros web`` streams at ``/stream?topic=/imshow/<name>``; the
first frame of each window prints one line with that URL. ``waitKey(delay)`` sleeps ``delay`` ms
(``delay <= 0`` waits until the node shuts down) and returns -1: there is no keyboard.

Frames are only converted and published while someone subscribes. An OpenCV with a GUI, a
``cv2.imshow`` someone else replaced, and ``MINROS_IMSHOW=off`` are left alone. ``install`` is
called when ``minros`` (``rospy``) is imported; it does not import cv2 itself, it patches cv2
when (and if) the program imports it.
"""

from __future__ import annotations

import importlib.machinery
import os
import re
import sys
import threading
import time
from typing import Any, Dict, Optional

ENV = "MINROS_IMSHOW"
URL_ENV = "MINROS_WEB_URL"
DEFAULT_URL = "http://localhost:9090"
TOPIC_PREFIX = "/imshow/"

_installed = False
_lock = threading.Lock()
_publishers: Dict[str, Any] = {}
_announced: set = set()
_no_node_warned = False


def topic_for(window: str) -> str:
    """The topic of a window: graph-name characters only (``My Window!`` -> ``/imshow/My_Window_``)."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", str(window)) or "window"
    if not name[0].isalpha():
        name = "w" + name
    return TOPIC_PREFIX + name


def displayable(image: Any) -> Any:
    """``(pixels, encoding)``: the 8-bit image imshow would show, and its ROS encoding."""
    import numpy as np

    array = np.asarray(image)
    if array.dtype == np.uint16 or array.dtype == np.int16:
        array = (array.astype(np.uint32) >> 8).astype(np.uint8)
    elif array.dtype in (np.float32, np.float64):
        array = np.clip(array * 255.0, 0, 255).astype(np.uint8)
    elif array.dtype == np.bool_:
        array = array.astype(np.uint8) * 255
    elif array.dtype != np.uint8:
        array = np.clip(array, 0, 255).astype(np.uint8)
    if array.ndim == 3 and array.shape[2] == 1:
        array = array[:, :, 0]
    if array.ndim == 2:
        return np.ascontiguousarray(array), "mono8"
    channels = array.shape[2]
    if channels == 4:
        return np.ascontiguousarray(array), "bgra8"
    if channels == 3:
        return np.ascontiguousarray(array), "bgr8"
    return np.ascontiguousarray(array[:, :, 0]), "mono8"


# The node runtime and the client library are imported when a window is first shown, not when
# `import rospy` installs the hook: importing minros (and every tool) stays light.


def _node_ready() -> bool:
    from minros import node

    return node.get_node_uri() is not None


def _publisher(window: str) -> Any:
    from minros.client.topics import Publisher  # not at import: `import rospy` stays light
    from sensor_msgs.msg import Image

    topic = topic_for(window)
    with _lock:
        pub = _publishers.get(topic)
        if pub is None:
            pub = Publisher(topic, Image, queue_size=1)
            _publishers[topic] = pub
    if topic not in _announced:
        _announced.add(topic)
        url = os.environ.get(URL_ENV, DEFAULT_URL).rstrip("/")
        print(f"[imshow] this OpenCV has no GUI: window '{window}' is published on {topic}; "
              f"watch it at {url}/stream_viewer?topic={topic} (run `minros web` to serve it; "
              f"{ENV}=off turns this off)", file=sys.stderr, flush=True)
    return pub


def imshow(winname: str, mat: Any) -> None:
    """Publish ``mat`` as the current frame of window ``winname``."""
    global _no_node_warned
    if not _node_ready():
        if not _no_node_warned:
            _no_node_warned = True
            print(f"[imshow] this OpenCV has no GUI, and window '{winname}' cannot be streamed "
                  "before rospy.init_node(): its frames are dropped", file=sys.stderr, flush=True)
        return
    pub = _publisher(winname)
    if pub.get_num_connections() == 0:
        return
    from sensor_msgs.msg import Image

    pixels, encoding = displayable(mat)
    msg = Image()
    from minros.client import rostime

    msg.header.stamp = rostime.get_rostime()
    msg.header.frame_id = str(winname)
    msg.height, msg.width = int(pixels.shape[0]), int(pixels.shape[1])
    msg.encoding = encoding
    msg.step = int(pixels.strides[0])
    msg.data = pixels.tobytes()
    pub.publish(msg)


def waitKey(delay: int = 0) -> int:  # noqa: N802 - OpenCV's name
    """No keyboard: wait ``delay`` ms (forever, until shutdown, when ``delay <= 0``); -1."""
    from minros import node

    if delay and delay > 0:
        time.sleep(delay / 1000.0)
        return -1
    node.wait_for_shutdown(None)
    return -1


def pollKey() -> int:  # noqa: N802
    return -1


def _noop(*_args: Any, **_kwargs: Any) -> None:
    return None


def destroyWindow(winname: str) -> None:  # noqa: N802
    pub = _publishers.pop(topic_for(winname), None)
    if pub is not None:
        pub.unregister()


def destroyAllWindows() -> None:  # noqa: N802
    for topic in list(_publishers):
        pub = _publishers.pop(topic, None)
        if pub is not None:
            pub.unregister()


def has_gui(cv2: Any) -> bool:
    """Whether this OpenCV build has a GUI backend (its build information lists one)."""
    try:
        info = cv2.getBuildInformation()
    except Exception:
        return True
    match = re.search(r"^\s*GUI:\s*(\S+)", info, re.MULTILINE)
    return not (match and match.group(1).upper() == "NONE")


def patch(cv2: Any) -> bool:
    """Replace the window functions of ``cv2`` when it has no GUI; True if patched."""
    if os.environ.get(ENV, "").lower() in ("off", "0", "no", "false"):
        return False
    if type(getattr(cv2, "imshow", None)).__name__ != "builtin_function_or_method":
        return False  # already replaced by someone (a test double, another bridge)
    if has_gui(cv2):
        return False
    cv2.imshow = imshow
    cv2.waitKey = waitKey
    cv2.waitKeyEx = waitKey
    cv2.pollKey = pollKey
    cv2.namedWindow = _noop
    cv2.destroyWindow = destroyWindow
    cv2.destroyAllWindows = destroyAllWindows
    return True


class _PatchingLoader:
    """A loader that runs cv2's own, then patches the module (the import protocol is duck-typed:
    subclassing importlib.abc would cost every `import rospy` importlib.resources)."""

    def __init__(self, loader: Any) -> None:
        self.loader = loader

    def create_module(self, spec: Any) -> Optional[Any]:
        return self.loader.create_module(spec)

    def exec_module(self, module: Any) -> None:
        self.loader.exec_module(module)
        try:
            patch(module)
        except Exception:  # never break `import cv2`
            pass


class _Cv2Finder:
    """Wraps the loader of the top-level ``cv2`` module so it is patched once imported."""

    def find_spec(self, fullname: str, path: Any, target: Any = None) -> Any:
        if fullname != "cv2":
            return None
        sys.meta_path.remove(self)
        try:
            spec = importlib.machinery.PathFinder.find_spec(fullname, path)
        finally:
            sys.meta_path.insert(0, self)
        if spec is None or spec.loader is None:
            return None
        patching: Any = _PatchingLoader(spec.loader)  # importlib's protocol, not its ABC
        spec.loader = patching
        return spec


def install() -> None:
    """Patch cv2 now if it is imported, else when it is (see the module doc)."""
    global _installed
    if _installed or os.environ.get(ENV, "").lower() in ("off", "0", "no", "false"):
        return
    _installed = True
    module = sys.modules.get("cv2")
    if module is not None:
        try:
            patch(module)
        except Exception:
            pass
        return
    sys.meta_path.insert(0, _Cv2Finder())
