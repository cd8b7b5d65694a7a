"""MINROSSHM's subscriber end: maps each segment read-only and reads every message from its slot
in place: ``uint8[]`` fields (``Image.data``, ``PointCloud2.data``) are memoryviews of the slot,
valid until the callbacks return, when the slot goes back to the publisher (DONE). A message
the callbacks kept (a list, message_filters, a latch) is made its own then: its views are
copied out (:func:`own`).
"""

from __future__ import annotations

import os
import socket
import struct
import sys
from typing import Any, Callable, Dict, List

from minros.msgs import reader_for
from minros.transport.base import FallBack
from minros.transport.shm.segment import Mapping
from minros.transport.streams import MSG_DONTWAIT, StreamTransport
from minros.transport.tcpros_base import negotiate
from minros.wire import shm, sockets, tcpros
from minros.wire.handshake import Handshake, Rejected

__all__ = ["ShmReceiver", "own"]

#: file descriptors one receive takes at most (a segment brings one)
_MAX_FDS = 4
_ANC_SIZE = socket.CMSG_SPACE(_MAX_FDS * 4) if hasattr(socket, "CMSG_SPACE") else 0
_U32 = struct.Struct("<I")


class ShmReceiver(StreamTransport):
    """The subscriber's end of its MINROSSHM connection to one publisher."""

    protocol = shm.PROTOCOL

    def __init__(self, stream: Any, topic: str) -> None:
        super().__init__(stream, topic)
        self.notices = shm.NoticeReader()
        self.bytes_received = 0
        self.maps: Dict[int, Mapping] = {}
        self.fds: List[int] = []
        self.held: List[bytes] = []  # DONE records of the frames given out last time
        self.unsent = b""  # of DONE records a non-blocking stream did not take
        self.latching = False
        self.peer_pid = sockets.peer_pid(stream)
        self.settle: Callable[[Any], None] | None = self._settle

    @property
    def stat_bytes(self) -> int:
        return self.bytes_received

    def info(self) -> str:
        return (f"MINROSSHM connection (shared memory) on Unix socket {self.fileno} to "
                f"[pid {self.peer_pid}]")

    def negotiate(self, handshake: Handshake, opening: Dict[str, str] | None = None) -> None:
        """The header exchange on the publisher's Unix socket. Any failure of it (refused by
        the publisher's admission, a silent or broken socket) is a FallBack: the subscriber
        connects over TCPROS at once instead, where a refusal that is the topic's, not the
        socket's, is said again."""
        try:
            self.header = negotiate(self.stream, handshake)
        except (Rejected, tcpros.HeaderError, OSError) as exc:
            raise FallBack(f"the publisher's shared-memory socket did not take the "
                           f"connection: {exc}") from None
        self.stream.settimeout(None)
        self.latching = self.header.get("latching", "0") == "1"

    def message_reader(self, data_class: Any) -> Callable[[Any], Any]:
        """Messages read in place: their byte arrays are views of the slot."""
        if not getattr(data_class, "_zero_copy", True):
            self.settle = None  # no byte or numeric array anywhere: nothing to settle
        read: Callable[[Any], Any] = reader_for(data_class, in_place=True)
        return read

    def _settle(self, msg: Any) -> None:
        """After the callbacks: a message kept beyond them (referenced from anywhere but the
        receive loop, or latched) gets copies of its views before the slot goes back."""
        # references: the receive loop's variable and what the call itself holds
        if self.latching or sys.getrefcount(msg) > 1 + _CALL_REFS:
            own(msg)

    def release(self) -> None:
        """Give back the slots of the frames given out last time (DONE): the caller is done
        with them. On a non-blocking stream what it does not take waits for the next call."""
        if self.held:
            self.unsent += b"".join(self.held)
            self.held = []
        if not self.unsent:
            return
        try:
            sent = self.stream.send(self.unsent, MSG_DONTWAIT)
        except BlockingIOError:
            return
        except OSError:  # the publisher went away: the next receive sees the end
            self.unsent = b""
            return
        self.unsent = self.unsent[sent:]
        if self.unsent and self.stream.gettimeout() is None:  # a blocking stream: all of it
            try:
                self.stream.sendall(self.unsent)
            except OSError:
                pass
            self.unsent = b""

    def receive(self) -> List[Any] | None:
        """The messages the publisher announced since the last call, whose slots are given
        back first (the receive loop is done with them)."""
        if self.held or self.unsent:
            self.release()
        if len(self.maps) > 1:
            newest = max(self.maps)
            for generation in [g for g in self.maps if g != newest]:
                self.maps.pop(generation).close()
        n, ancdata, flags, _ = self.stream.recvmsg_into([self.notices.space()], _ANC_SIZE)
        self._take_fds(ancdata)
        if flags & getattr(socket, "MSG_CTRUNC", 0):
            raise FallBack("a file descriptor the publisher sent was lost (too many open files?)")
        if not n:
            if self.notices.pending:
                raise tcpros.FrameError("the publisher stopped in the middle of a record")
            return None
        self.bytes_received += n
        try:
            return self._frames(self.notices.received(n))
        except shm.ShmError as exc:
            raise FallBack(f"the publisher broke the shared-memory protocol: {exc}") from None

    def _take_fds(self, ancdata: Any) -> None:
        for level, kind, data in ancdata:
            if level == socket.SOL_SOCKET and kind == socket.SCM_RIGHTS:
                count = len(data) // 4
                self.fds.extend(struct.unpack(f"{count}i", data[:count * 4]))
        if len(self.fds) > _MAX_FDS:
            self._close_fds()
            raise FallBack("the publisher sent more file descriptors than segments")

    def _close_fds(self) -> None:
        fds, self.fds = self.fds, []
        for fd in fds:
            os.close(fd)

    def _frames(self, notices: List[Any]) -> List[Any]:
        if not self.fds and notices and all(n.__class__ is bytes for n in notices):
            return notices  # only small messages: the usual case of a small-message topic
        frames: List[Any] = []
        for notice in notices:
            cls = notice.__class__
            if cls is bytes:
                frames.append(notice)
            elif cls is shm.Slot:
                mapping = self.maps.get(notice.generation)
                if mapping is None:
                    raise shm.ShmError(f"a slot of segment {notice.generation}, which never came")
                seg = mapping.segment
                offset, length = notice.offset, notice.length
                if notice.slot >= seg.slots or length < 4 or offset + length > seg.slot_size:
                    raise shm.ShmError(f"slot {notice.slot} ({length} bytes at {offset}) is "
                                       f"outside the segment of {seg.slots} slots of "
                                       f"{seg.slot_size} bytes")
                start = shm.HEADER_SIZE + notice.slot * seg.slot_size + offset
                frame = mapping.view[start:start + length]
                self.held.append(shm.done(notice.generation, notice.slot))
                if _U32.unpack_from(frame)[0] != length - 4:
                    raise shm.ShmError(f"slot {notice.slot} does not hold the message announced")
                frames.append(frame[4:])
            elif cls is shm.Segment:
                if not self.fds:
                    raise shm.ShmError("a segment came without its file descriptor")
                fd = self.fds.pop(0)
                if notice.generation in self.maps:
                    os.close(fd)
                    raise shm.ShmError(f"segment {notice.generation} announced twice")
                self.maps[notice.generation] = Mapping(notice, fd)
            else:  # Fallback
                raise FallBack(f"the publisher gave up on shared memory: {notice}")
        if self.fds and not self.notices.pending:
            self._close_fds()
            raise shm.ShmError("a file descriptor came without a segment")
        return frames

    def close(self) -> None:
        if self.done:
            return
        self.done = True
        try:
            self.stream.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        sockets.close(self.stream)
        self._close_fds()
        maps, self.maps = self.maps, {}
        for mapping in maps.values():
            mapping.close()


class _RefProbe:
    def refs(self, obj: Any) -> int:
        return sys.getrefcount(obj)


def _call_refs() -> int:
    """The references a call like ``settle(msg)`` (a bound method in a local) adds to its
    argument, as ``getrefcount`` sees them inside: the parameter and getrefcount's argument,
    and before Python 3.11 the caller's stack slot too."""
    obj = object()
    refs = _RefProbe().refs
    return refs(obj) - 1  # less the caller's own variable


#: measured, not assumed: the calling convention changed in 3.11 (and may again)
_CALL_REFS = _call_refs()


def own(msg: Any) -> None:
    """Give ``msg`` (and the messages it holds) copies of every field that is a view of
    received memory: memoryviews become bytes, numpy views arrays of their own."""
    if not getattr(msg.__class__, "_zero_copy", True):
        return  # no byte or numeric arrays anywhere in it
    stack = [msg]
    while stack:
        obj = stack.pop()
        for name in getattr(obj.__class__, "__slots__", ()):
            value: Any = getattr(obj, name, None)
            cls = value.__class__
            if cls is memoryview:
                setattr(obj, name, value.tobytes())
            elif cls is list:
                stack.extend(item for item in value if hasattr(item, "_slot_types"))
            elif hasattr(value, "_slot_types"):
                stack.append(value)
            elif getattr(value, "base", None) is not None and hasattr(value, "__array_interface__"):
                setattr(obj, name, value.copy())

