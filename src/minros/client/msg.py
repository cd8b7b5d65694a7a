"""Messages as the client library sends them: rospy's AnyMsg, its publish-argument rules, the
Header it stamps, and serialization into one length-prefixed frame, for topics and services.

A frame is serialized once per publish and handed to every connection: ``bytes`` for a small
message (one join), or a tuple of buffers (length prefix first) that a transport sends with
``sendmsg`` without joining them, so a big array goes out without a copy. A service request is
the same frame, and a response the same after its ok byte (:func:`serialize_frame`).
"""

from __future__ import annotations

import struct
from typing import Any, List

from minros.exceptions import ROSException, ROSSerializationException
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


class _Parts:
    """A write-only sink for ``Message.serialize`` that keeps what is written without joining
    it: big pieces (array and string fields) as they are, runs of small ones joined as they
    come, so a message of many small fields does not hold thousands of objects. With
    ``snapshot`` a mutable big piece is copied (a topic's frame may wait in a queue after
    publish returns); without, it is kept as a byte view (a service's is sent at once)."""

    __slots__ = ("_parts", "_small", "_small_size", "size", "snapshot")

    def __init__(self, snapshot: bool = True) -> None:
        self._parts: list = []
        self._small: list = []
        self._small_size = 0
        self.size = 0
        self.snapshot = snapshot

    def write(self, data: Any) -> None:
        if data.__class__ is not bytes:
            data = _piece(data, self.snapshot)
        size = len(data)
        self.size += size
        if size < _SMALL_PART:
            self._small.append(data)
            self._small_size += size
            if self._small_size >= _JOIN_LIMIT:
                self._flush()
            return
        self._flush()
        self._parts.append(data)

    def _flush(self) -> None:
        if self._small:
            self._parts.append(b"".join(self._small))
            self._small = []
            self._small_size = 0

    def frame(self, head: bytes) -> Any:
        """``head``, the length prefix and everything written: bytes when small, else a tuple
        of buffers (the prefix first, joined with a small first piece)."""
        self._flush()
        prefix = head + _U32.pack(self.size)
        parts = self._parts
        if self.size <= _JOIN_LIMIT:
            return b"".join([prefix, *parts])
        if parts[0].__class__ is bytes and len(parts[0]) < _SMALL_PART:
            parts[0] = prefix + parts[0]
        else:
            parts.insert(0, prefix)
        return tuple(parts)


def _piece(data: Any, snapshot: bool) -> Any:
    """A written buffer as a frame may hold it: a copy (``snapshot``), or a byte-wise view, so
    that a partial send can slice it (``cast`` needs C order: anything else is copied)."""
    if snapshot:
        return bytes(data)
    view = memoryview(data)
    if view.format != "B" or view.ndim != 1:
        view = view.cast("B") if view.c_contiguous else memoryview(view.tobytes())
    return view


class _Discard:
    """Sink for re-running a failed serialization to get the message's own error text."""

    @staticmethod
    def write(_data: Any) -> None:
        pass


def serialize_frame(msg: Any, head: bytes = b"", snapshot: bool = True) -> Any:
    """``msg`` serialized into one frame: ``head`` (a service response's ok byte), the length
    prefix and the body; ``bytes`` for small messages, else a tuple of buffers (the prefix at
    the start of the first) that ``sendmsg`` writes without joining them. ``snapshot``: big
    mutable pieces are copied (see :class:`_Parts`; a topic's frame may wait in a queue).
    rospy's ROSSerializationException, naming the field, when one cannot be serialized."""
    parts_of = getattr(msg, "_serialize_parts", None)
    if parts_of is not None:
        parts: list = []
        try:
            parts_of(parts.append)
        except NotImplementedError:
            # a hand-written genpy-style class: it subclasses Message but only its
            # serialize() is real (the base _serialize_parts is a stub)
            parts_of = None
        except SERIALIZE_ERRORS as exc:
            _raise_field_error(msg, exc)
        else:
            if not msg._zero_copy:
                # no array fields that could be views of big buffers (strings, numbers, nested
                # messages): one join, the usual case for every small message
                body = b"".join(parts)
                size = len(body)
                if size <= _JOIN_LIMIT:
                    return (head + _U32.pack(size) + body) if head else _U32.pack(size) + body
                return (head + _U32.pack(size), body)
            return _frame(parts, head, snapshot)
    writer = _Parts(snapshot)
    try:
        msg.serialize(writer)
    except ROSSerializationException as exc:
        if exc.__class__ is ROSSerializationException:
            raise
        raise ROSSerializationException(str(exc)) from None
    except SERIALIZE_ERRORS as exc:
        raise ROSSerializationException(str(exc)) from None
    return writer.frame(head)


def _raise_field_error(msg: Any, exc: BaseException) -> None:
    """Serialize ``msg`` again through serialize(), whose error names the bad field, and raise
    that as ROSSerializationException."""
    try:
        msg.serialize(_Discard)
    except SERIALIZE_ERRORS as named:
        raise ROSSerializationException(str(named)) from None
    raise ROSSerializationException(str(exc)) from None


def _frame(parts: list, head: bytes, snapshot: bool) -> Any:
    """The frame of a generated class's serialized ``parts``."""
    size = 0
    for part in parts:
        size += len(part) if part.__class__ is bytes else memoryview(part).nbytes
    prefix = head + _U32.pack(size)
    if size <= _JOIN_LIMIT:
        parts.insert(0, prefix)
        return b"".join(parts)
    out: list = []
    small: list = [prefix]
    for part in parts:  # coalesce the many small field writes around the big ones
        n = len(part) if part.__class__ is bytes else memoryview(part).nbytes
        if n < _SMALL_PART:
            small.append(part)
            continue
        if small:
            out.append(b"".join(small))
            small = []
        out.append(part if part.__class__ is bytes else _piece(part, snapshot))
    if small:
        out.append(b"".join(small))
    return tuple(out)


def frame_len(frame: Any) -> int:
    """The bytes of a frame, its length prefix included."""
    if type(frame) is tuple:
        return sum(len(p) for p in frame)
    return len(frame)
