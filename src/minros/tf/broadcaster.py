"""tf2_ros's broadcasters: transforms out on ``/tf`` and, latched, on ``/tf_static``."""

from __future__ import annotations

import threading
from typing import Any, Dict, List

import minros


def _as_list(transform: Any) -> List[Any]:
    return list(transform) if isinstance(transform, (list, tuple)) else [transform]


class TransformBroadcaster:
    """Publish geometry_msgs/TransformStamped on ``/tf`` (one TFMessage per call)."""

    def __init__(self, queue_size: int = 100) -> None:
        from tf2_msgs.msg import TFMessage

        self._message = TFMessage
        self.pub_tf = minros.Publisher("/tf", TFMessage, queue_size=queue_size)

    def sendTransform(self, transform: Any) -> None:  # noqa: N802 (tf2_ros's name)
        """Send a transform, or a list of transforms."""
        self.pub_tf.publish(self._message(_as_list(transform)))


# /tf_static is latched, and a subscriber that connects late receives only the last message:
# so every static transform this node ever sent goes out in each message (tf2_ros's C++
# broadcaster does the same), keyed by child frame so that a resend replaces the old one.
_static_lock = threading.Lock()
_static_frames: Dict[str, Any] = {}


class StaticTransformBroadcaster:
    """Publish transforms valid at any time, latched on ``/tf_static``."""

    def __init__(self, queue_size: int = 100) -> None:
        from tf2_msgs.msg import TFMessage

        self._message = TFMessage
        self.pub_tf = minros.Publisher("/tf_static", TFMessage, queue_size=queue_size, latch=True)

    def sendTransform(self, transform: Any) -> None:  # noqa: N802 (tf2_ros's name)
        """Send a transform, or a list of them; the message carries all of this node's."""
        with _static_lock:
            for each in _as_list(transform):
                child = each.child_frame_id
                _static_frames[child[1:] if child.startswith("/") else child] = each
            message = self._message(list(_static_frames.values()))
            self.pub_tf.publish(message)


__all__ = ["TransformBroadcaster", "StaticTransformBroadcaster"]
