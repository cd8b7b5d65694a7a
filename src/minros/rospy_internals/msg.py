"""rospy.msg: framing messages into and out of rospy's connection buffers (rospy.msg's
serialize_message and deserialize_messages), over minros's message classes."""

from __future__ import annotations

import logging
import struct
import traceback
from typing import Any, List, Optional

from minros.client.msg import AnyMsg, args_kwds_to_message, stamp_header
from minros.exceptions import DeserializationError, ROSSerializationException
from minros.msgs.message import reader_for

__all__ = ["AnyMsg", "args_kwds_to_message", "deserialize_messages", "serialize_message"]

_U32 = struct.Struct("<I")
_logger = logging.getLogger("rospy.msg")


def serialize_message(b: Any, seq: int, msg: Any) -> None:
    """Write ``msg`` into buffer ``b`` at its position as one frame (length prefix first); a
    message with a Header gets ``seq`` (and frame_id "0" for None), as every rospy send does."""
    start = b.tell()
    b.seek(start + 4)  # the length, once known
    stamp_header(msg, seq)
    try:
        msg.serialize(b)
    except struct.error as exc:
        raise ROSSerializationException(exc) from None
    end = b.tell()
    b.seek(start)
    b.write(_U32.pack(end - 4 - start))
    b.seek(end)


def deserialize_messages(b: Any, msg_queue: List[Any], data_class: Any,
                         queue_size: Optional[int] = None, max_msgs: Optional[int] = None,
                         start: int = 0) -> None:
    """Append the messages of the complete frames in ``b`` (from ``start`` to its position)
    to ``msg_queue``, keeping only the newest ``queue_size``; what remains of an incomplete
    frame is moved to ``start``. DeserializationError for a bad frame. (The transport reading
    into ``b`` bounds what a peer may announce: see TCPROSTransport.receive_once.)"""
    try:
        end = b.tell()
        if end - start < 4:
            return
        b.seek(start)
        frames: List[bytes] = []
        pos = start
        while end - pos >= 4:
            (size,) = _U32.unpack(b.read(4))
            if end - pos - 4 < size:
                break
            frames.append(b.read(size))
            pos += 4 + size
            if max_msgs and len(frames) >= max_msgs:
                break
        if queue_size is not None:
            frames = frames[-queue_size:]
        read = reader_for(data_class)
        msg_queue.extend(read(frame) for frame in frames)
        if queue_size is not None:
            del msg_queue[:-queue_size]
        if pos == end:
            b.seek(start)
            b.truncate(start)
        elif pos != start:
            b.seek(pos)
            rest = b.read(end - pos)
            b.seek(start)
            b.write(rest)
            b.truncate(start + len(rest))
        else:
            b.seek(end)
    except Exception as exc:
        _logger.error("cannot deserialize message: EXCEPTION %s", traceback.format_exc())
        raise DeserializationError(f"cannot deserialize: {exc}") from None
