"""Messages as the client library sends them: rospy's AnyMsg, its publish-argument rules, the
Header it stamps, and serialization into one length-prefixed frame.

A frame is serialized once per publish and handed to every connection: ``bytes`` for a small
message (one join), or a tuple of buffers (length prefix first) that a transport sends with
``sendmsg`` without joining them, so a big array goes out without a copy.
"""

from __future__ import annotations

import struct
from typing import Any, List

from minros.exceptions import ROSException, ROSSerializationException, SerializationError
from minros.msgs.message import SERIALIZE_ERRORS
from minros.names import ANYTYPE

__all__ = ["AnyMsg", "args_kwds_to_message", "frame_len", "serialize_frame", "stamp_header"]

#: frames up to this size are joined into one bytes object; larger keep their parts (no copy)
_JOIN_LIMIT = 65536
#: serialized pieces smaller than this are joined with their neighbours (fewer buffers)
_SMALL_PART = 4096
_U32 = struct.Struct("<I")


class AnyMsg:
    """Receives any message type as raw bytes (``_buff``); publishing it re-sends those bytes."""

    __slots__ = ("_buff", "_connection_header")
    _md5sum = ANYTYPE
    _type = ANYTYPE
    _has_header = False
    _full_text = ""
    _slot_types: List[str] = []

    def __init__(self, *args: Any) -> None:
        if len(args) > 1:
            raise ROSException("AnyMsg does not accept arguments")
        self._buff = args[0] if args else None

    def serialize(self, buff: Any) -> None:
        if self._buff is None:
            raise ROSSerializationException("AnyMsg is not initialized")
        buff.write(self._buff)

    def deserialize(self, data: Any) -> AnyMsg:
        self._buff = data
        return self


def stamp_header(msg: Any, seq: int) -> None:
    """What rospy does to every message it sends (topic, request or response): a message with
    a std_msgs/Header gets the sender's sequence number, and a None frame_id becomes "0"."""
    if getattr(msg, "_has_header", False):
        header = msg.header
        header.seq = seq
        if header.frame_id is None:
            header.frame_id = "0"


def args_kwds_to_message(data_class: Any, args: tuple, kwds: dict) -> Any:
    """rospy's publish(msg | *fields | **fields) convention."""
    if len(args) == 1 and not kwds and args[0].__class__ is data_class:
        return args[0]
    if args and kwds:
        raise TypeError("publish() can be called with arguments or keywords, but not both.")
    if kwds:
        return data_class(**kwds)
    if len(args) == 1:
        arg = args[0]
        if isinstance(arg, data_class):
            return arg
        if hasattr(arg, "_type") and hasattr(arg, "_md5sum") and not isinstance(arg, data_class):
            if getattr(arg, "_type", None) != getattr(data_class, "_type", None):
                raise TypeError(f"expected [{data_class._type}] but got [{arg._type}]")
            return arg
        return data_class(arg)
    return data_class(*args)


class _Chunks:
    """A write-only buffer that keeps the parts a message writes (no concatenation)."""

    __slots__ = ("parts", "size")

    def __init__(self) -> None:
        self.parts: list = []
        self.size = 0

    def write(self, data: Any) -> int:
        if type(data) is not bytes:
            data = bytes(data)  # mutable buffers are snapshotted: the frame may wait in a queue
        self.parts.append(data)
        self.size += len(data)
        return len(data)


class _Discard:
    """Sink for re-running a failed serialization to get the message's own error text."""

    @staticmethod
    def write(_data: Any) -> None:
        pass


def serialize_frame(msg: Any) -> Any:
    """Serialize ``msg`` into one frame: ``bytes`` for small messages, else a tuple of buffers
    (length prefix first) that ``sendmsg`` writes without joining them."""
    parts_of = getattr(msg, "_serialize_parts", None)
    if parts_of is None:  # not a minros message class (AnyMsg)
        parts = _parts_written_by(msg)
    else:
        parts = []
        try:
            parts_of(parts.append)
        except NotImplementedError:
            # a hand-written genpy-style class: it subclasses Message but only its
            # serialize() is real (the base _serialize_parts is a stub)
            parts = _parts_written_by(msg)
        except SERIALIZE_ERRORS:
            _raise_field_error(msg)
            raise
        else:
            if not msg._zero_copy:
                # no array fields that could be views of big buffers (strings, numbers, nested
                # messages): one join, the usual case for every small message
                body = b"".join(parts)
                size = len(body)
                if size <= _JOIN_LIMIT:
                    return _U32.pack(size) + body
                return (_U32.pack(size), body)
    size = 0
    for part in parts:
        size += len(part) if part.__class__ is bytes else memoryview(part).nbytes
    if size <= _JOIN_LIMIT:
        parts.insert(0, _U32.pack(size))
        return b"".join(parts)
    out = [_U32.pack(size)]
    small: list = []
    for part in parts:  # coalesce the many small field writes around the big ones
        n = len(part) if part.__class__ is bytes else memoryview(part).nbytes
        if n < _SMALL_PART:
            small.append(part)
            continue
        if small:
            out.append(b"".join(small))
            small = []
        # mutable buffers are snapshotted: the frame may wait in a queue after publish returns
        out.append(part if part.__class__ is bytes else bytes(part))
    if small:
        out.append(b"".join(small))
    return tuple(out)


def _parts_written_by(msg: Any) -> list:
    """What ``msg.serialize(buff)`` writes, as a list of ``bytes`` (copies: a frame may wait in
    a queue after publish returns)."""
    chunks = _Chunks()
    try:
        msg.serialize(chunks)
    except ROSSerializationException:
        raise
    except SERIALIZE_ERRORS as exc:
        raise ROSSerializationException(str(exc)) from None
    return chunks.parts


def _raise_field_error(msg: Any) -> None:
    """Serialize ``msg`` again through serialize(), whose error names the bad field, and raise
    that as ROSSerializationException."""
    try:
        msg.serialize(_Discard)
    except SerializationError as exc:
        raise ROSSerializationException(str(exc)) from None
    except SERIALIZE_ERRORS as exc:
        raise ROSSerializationException(str(exc)) from None


def frame_len(frame: Any) -> int:
    """The bytes of a frame, its length prefix included."""
    if type(frame) is tuple:
        return sum(len(p) for p in frame)
    return len(frame)
