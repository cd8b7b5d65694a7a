"""tf2_ros's TransformListener: feeds ``/tf`` and ``/tf_static`` into a buffer.

The callbacks run in the subscriber's receive thread, so they stay short: one clock read
for the jump-back check, then every transform of the message inserted under one lock. The
authority of a transform is the publishing node (``callerid`` of the connection header).
"""

from __future__ import annotations

import threading
from typing import Any

import minros

DEFAULT_AUTHORITY = "default_authority"


class TransformListener:
    """Subscribe to ``/tf`` and ``/tf_static`` and insert what arrives into ``buffer``.

    When ROS time goes backwards (a bag restarting, ``/clock`` jumping back) the buffer is
    cleared with a warning, as tf2_ros does, so old lookups do not mix two timelines.
    """

    def __init__(self, buffer: Any, queue_size: Any = None, buff_size: int = 65536,
                 tcp_nodelay: bool = False) -> None:
        from tf2_msgs.msg import TFMessage

        self.buffer = buffer
        self.last_update = minros.get_time()
        self.last_update_lock = threading.Lock()
        insert_many = getattr(buffer, "set_transforms", None)
        if insert_many is not None:
            self._insert = insert_many
        else:  # a user buffer with tf2's API only
            def insert(transforms: Any, authority: str, is_static: bool) -> None:
                setter = buffer.set_transform_static if is_static else buffer.set_transform
                for transform in transforms:
                    setter(transform, authority)

            self._insert = insert
        self.tf_sub = minros.Subscriber("/tf", TFMessage, self.callback, queue_size=queue_size,
                                        buff_size=buff_size, tcp_nodelay=tcp_nodelay)
        self.tf_static_sub = minros.Subscriber("/tf_static", TFMessage, self.static_callback,
                                               queue_size=queue_size, buff_size=buff_size,
                                               tcp_nodelay=tcp_nodelay)

    def __del__(self) -> None:
        try:
            self.unregister()
        except Exception:  # interpreter shutdown: the subscribers may be gone already
            pass

    def unregister(self) -> None:
        """Stop listening."""
        self.tf_sub.unregister()
        self.tf_static_sub.unregister()

    def check_for_reset(self) -> None:
        """Clear the buffer when ROS time went backwards since the last message."""
        with self.last_update_lock:
            now = minros.get_time()
            if now < self.last_update:
                minros.logwarn("Detected jump back in time of %fs. Clearing TF buffer."
                               % (self.last_update - now))
                self.buffer.clear()
            self.last_update = now

    @staticmethod
    def _authority(msg: Any) -> str:
        header = getattr(msg, "_connection_header", None)
        return header.get("callerid", DEFAULT_AUTHORITY) if header else DEFAULT_AUTHORITY

    def callback(self, data: Any) -> None:
        self.check_for_reset()
        self._insert(data.transforms, self._authority(data), False)

    def static_callback(self, data: Any) -> None:
        self.check_for_reset()
        self._insert(data.transforms, self._authority(data), True)


__all__ = ["TransformListener"]
