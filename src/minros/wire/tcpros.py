"""TCPROS as pure functions: connection headers, length-prefixed framing, service responses.

No sockets here (sans-IO, like h11): the transports (``minros.transport``), the node's TCPROS
server and ``minros.client.services`` only move bytes in and out of these objects; the order of
the header exchange is :mod:`minros.wire.handshake`.

Wire format (all integers little-endian ``uint32``):

* connection header: ``total_len`` then repeated ``field_len`` + ``b"key=value"``;
* topic data: ``len`` + serialized message, back to back;
* service response: ``uint8 ok`` + ``len`` + payload (``ok=0``: the payload is an error string).

Every length read from the wire is checked against an explicit limit before anything is
allocated for it, and large frames grow their buffer only as their bytes actually arrive.
"""

from __future__ import annotations

import struct
from typing import Any, Dict, List, Mapping, Tuple, Union

from minros.exceptions import TransportException

__all__ = [
    "DEFAULT_MAX_FRAME",
    "DEFAULT_MAX_HEADER",
    "FrameError",
    "FrameReader",
    "HeaderError",
    "TCPROS",
    "decode_header",
    "encode_error_header",
    "encode_frame",
    "encode_header",
    "encode_service_error",
    "encode_service_response",
    "frame_prefix",
    "publisher_header_error",
    "read_header_block",
    "service_header_error",
    "subscriber_header_error",
]

#: protocol name used in requestTopic
TCPROS = "TCPROS"
#: connection headers are small (a few KiB incl. message_definition); 1 MiB is generous
DEFAULT_MAX_HEADER = 1 << 20
#: roscpp refuses messages above 1 GB; the same limit here
DEFAULT_MAX_FRAME = 1_000_000_000
#: a frame up to this size is received into the shared buffer, larger ones get their own
DEFAULT_BUFF_SIZE = 65536
#: the largest shared receive buffer; frames that do not fit get their own buffer
MAX_SHARED_BUFFER = 256 << 10
#: a big frame's own buffer starts at most this large and then doubles as bytes arrive,
#: so a lying length field costs at most twice what the peer really sent
_FIRST_CHUNK = 16 << 20
#: the md5 wildcard (rostopic echo, AnyMsg)
ANYTYPE = "*"

_U32 = struct.Struct("<I")
_OK_LEN = struct.Struct("<BI")


class HeaderError(TransportException):
    """A connection header is malformed or too large."""


class FrameError(TransportException):
    """A length-prefixed frame is malformed, too large, or cut short."""


BytesLike = Union[bytes, bytearray, memoryview]


# ---------------------------------------------------------------------------------------------
# connection header


def encode_header(fields: Mapping[str, str]) -> bytes:
    """Encode a connection header, length prefix included (fields sorted, as rospy does)."""
    parts = []
    for key in sorted(fields):
        if not isinstance(key, str) or not key or "=" in key:
            raise HeaderError(f"illegal connection header key {key!r}")
        value = fields[key]
        if not isinstance(value, str):
            value = str(value)
        item = f"{key}={value}".encode()
        parts.append(_U32.pack(len(item)))
        parts.append(item)
    body = b"".join(parts)
    return _U32.pack(len(body)) + body


def decode_header(block: BytesLike) -> Dict[str, str]:
    """Decode the fields of a connection header (``block`` excludes the total length).

    Raises HeaderError on a field that overruns the block, is empty, lacks ``=``, or is not
    UTF-8. Later duplicates of a key win, as in rospy.
    """
    view = memoryview(block).cast("B") if not isinstance(block, bytes) else block
    size = len(view)
    fields: Dict[str, str] = {}
    pos = 0
    while pos < size:
        if size - pos < 4:
            raise HeaderError(f"connection header truncated: {size - pos} stray byte(s) at offset {pos}")
        (flen,) = _U32.unpack_from(view, pos)
        pos += 4
        if flen == 0:
            raise HeaderError(f"connection header has an empty field at offset {pos - 4}")
        if flen > size - pos:
            raise HeaderError(
                f"connection header field of {flen} bytes overruns the header ({size - pos} left)")
        raw = bytes(view[pos:pos + flen])
        pos += flen
        key, sep, value = raw.partition(b"=")
        if not sep:
            raise HeaderError(f"connection header field without '=': {raw[:40]!r}")
        try:
            fields[key.decode()] = value.decode()
        except UnicodeDecodeError as exc:
            raise HeaderError(f"connection header field is not UTF-8: {raw[:40]!r}") from exc
    return fields


def read_header_block(data: BytesLike, max_size: int = DEFAULT_MAX_HEADER
                      ) -> Tuple[Dict[str, str], int] | None:
    """Parse a whole header (length prefix included) from the start of ``data``.

    Returns ``(fields, bytes_consumed)``, or None when more bytes are needed.
    """
    if len(data) < 4:
        return None
    (size,) = _U32.unpack_from(data, 0)
    if size > max_size:
        raise HeaderError(f"connection header of {size} bytes exceeds the limit of {max_size}")
    if len(data) < 4 + size:
        return None
    return decode_header(memoryview(data)[4:4 + size]), 4 + size


def encode_error_header(message: str) -> bytes:
    """The rejection header: only ``error=<message>`` (the peer then closes)."""
    return encode_header({"error": message})


# ---------------------------------------------------------------------------------------------
# header validation (the error texts of rospy, so tools and tests see the same words)


def publisher_header_error(header: Mapping[str, str], caller_id: str,
                           publications: Mapping[str, Tuple[str, str]]) -> str | None:
    """Check a subscriber's header against this node's publications.

    ``publications`` maps resolved topic -> (type, md5sum). Returns the error text to send
    back in an ``error=`` header, or None if the connection is acceptable.
    """
    for required in ("topic", "md5sum", "callerid"):
        if required not in header:
            return f"Missing required '{required}' field"
    topic = header["topic"]
    pub = publications.get(topic)
    if pub is None:
        listed = [[name, kind] for name, (kind, _md5) in publications.items()]
        return f"[{caller_id}] is not a publisher of [{topic}]. Topics are {listed}"
    actual_type, actual_md5 = pub
    md5sum = header["md5sum"]
    if md5sum != ANYTYPE and actual_md5 != ANYTYPE and md5sum != actual_md5:
        requested_type = header.get("type", actual_type)
        if requested_type != actual_type:
            return f"topic types do not match: [{requested_type}] vs. [{actual_type}]"
        return (f"Client [{header['callerid']}] wants topic [{topic}] to have datatype/md5sum "
                f"[{requested_type}/{md5sum}], but our version has [{actual_type}/{actual_md5}]"
                " Dropping connection.")
    return None


def subscriber_header_error(header: Mapping[str, str], topic: str, md5sum: str,
                            msg_type: str) -> str | None:
    """Check a publisher's reply header on the subscriber side; None if acceptable."""
    if "error" in header:
        return f"remote error reported: {header['error']}"
    for required in ("md5sum", "type"):
        if required not in header:
            return f"header missing required field [{required}]"
    theirs = header["md5sum"]
    if md5sum != ANYTYPE and theirs != ANYTYPE and theirs != md5sum:
        # roscpp's subscriber-side wording for the same mismatch
        return (f"md5sum mismatch on topic [{topic}]: publisher has [{header['type']}/{theirs}], "
                f"subscriber expects [{msg_type}/{md5sum}]")
    return None


def service_header_error(header: Mapping[str, str], service: str, md5sum: str) -> str | None:
    """Check a service client's header on the server side; None if acceptable."""
    for required in ("service", "md5sum", "callerid"):
        if required not in header:
            return f"Missing required '{required}' field"
    if header["service"] != service:
        return f"request from [{header['callerid']}]: service name does not match: [{header['service']}] vs. [{service}]"
    theirs = header["md5sum"]
    if theirs != ANYTYPE and md5sum != ANYTYPE and theirs != md5sum:
        return f"request from [{header['callerid']}]: md5sums do not match: [{theirs}] vs. [{md5sum}]"
    return None


# ---------------------------------------------------------------------------------------------
# framing


def frame_prefix(size: int) -> bytes:
    """The 4-byte length prefix of a frame of ``size`` bytes."""
    return _U32.pack(size)


def encode_frame(payload: BytesLike) -> bytes:
    """A length-prefixed frame (topic message or service request)."""
    return _U32.pack(len(payload)) + bytes(payload)


def encode_service_response(payload: BytesLike) -> bytes:
    """A successful service response: ``ok=1`` + length + serialized response."""
    return _OK_LEN.pack(1, len(payload)) + bytes(payload)


def encode_service_error(message: str) -> bytes:
    """A failed service response: ``ok=0`` + length + UTF-8 error string."""
    raw = message.encode("utf-8", "replace")
    return _OK_LEN.pack(0, len(raw)) + raw


class FrameReader:
    """Reads length-prefixed frames out of a byte stream without doing any I/O itself.

    Use::

        reader = FrameReader()
        while True:
            n = sock.recv_into(reader.recv_buffer())
            if not n: reader.eof(); break        # raises FrameError if mid-frame
            reader.received(n)
            for frame in reader.frames(): ...

    Small frames are parsed out of one preallocated buffer and returned as ``bytes``. A frame
    larger than the buffer is received straight into its own ``bytearray`` (no further copy)
    and that bytearray is handed over, so message fields may keep views of it (zero-copy).
    With ``reuse_big=True`` the consumer promises to be done with each big frame before it
    asks for the next receive buffer, and same-size big frames share one bytearray.

    ``ok_byte=True`` reads service responses: each frame is then ``(ok, payload)``.
    ``max_frame`` can be changed between frames (e.g. header limit first, then messages).
    """

    __slots__ = ("_buf", "_view", "_start", "_end", "_big", "_big_len", "_big_fill",
                 "_big_ok", "max_frame", "ok_byte", "_ready", "bytes_received", "_error",
                 "reuse_big", "_spare", "first_chunk")

    def __init__(self, max_frame: int = DEFAULT_MAX_FRAME, buff_size: int = DEFAULT_BUFF_SIZE,
                 ok_byte: bool = False, reuse_big: bool = False,
                 first_chunk: int = _FIRST_CHUNK) -> None:
        # The shared buffer only ever holds small frames; anything larger goes to a buffer of
        # its own, so a huge buff_size (rospy users pass 2**24 for images) must not turn big
        # frames into copies out of the shared buffer.
        buff_size = min(max(buff_size, 16), MAX_SHARED_BUFFER)
        self._buf = bytearray(buff_size)
        self._view = memoryview(self._buf)
        self._start = 0  # first unread byte
        self._end = 0  # one past the last received byte
        self._big: bytearray | None = None
        self._big_len = 0
        self._big_fill = 0
        self._big_ok = 1
        self.max_frame = max_frame
        self.ok_byte = ok_byte
        self._ready: List[Any] = []
        self.bytes_received = 0
        self._error: FrameError | None = None
        # reuse_big=True: the consumer is done with a big frame before it asks for more data
        # (a subscriber whose messages copy their fields out), so the next big frame of the
        # same size is received into the same bytearray: no allocation and zero-fill per image
        self.reuse_big = reuse_big
        self._spare: bytearray | None = None
        #: a big frame's own buffer starts at most this large, then doubles as bytes arrive
        self.first_chunk = first_chunk

    # -- I/O side --------------------------------------------------------------------------

    def recv_buffer(self) -> memoryview:
        """The writable region the next ``recv_into`` should fill (never empty)."""
        if self._error is not None:
            raise self._error
        big = self._big
        if big is not None:
            if self._big_fill == len(big):  # grow a big frame's buffer as its bytes arrive
                new_size = min(self._big_len, len(big) * 2)
                big.extend(bytes(new_size - len(big)))
            return memoryview(big)[self._big_fill:]
        end = self._end
        if not end:  # everything consumed: the usual case between small messages
            return self._view
        if end == len(self._buf):
            self._compact()
        return self._view[self._end:]

    def received(self, n: int) -> None:
        """Account for ``n`` bytes written into the last ``recv_buffer()``; ``frames()`` then
        pops the completed frames."""
        self._ready = self.received_frames(n)

    def received_frames(self, n: int) -> List[Any]:
        """``received(n)`` and ``frames()`` in one call (the subscriber's hot path): the frames
        completed so far. An error in the data is raised by the next call, once the good
        frames before it are out."""
        self.bytes_received += n
        if self._big is not None:
            self._big_fill += n
            if self._big_fill == self._big_len:
                self._finish_big()
        else:
            self._end += n
            try:
                if not self.ok_byte:
                    end = self._end
                    if not self._start and end >= 4 and not self._ready:
                        # one whole message in one recv, the usual case: one unpack, one slice
                        (size,) = _U32.unpack_from(self._buf, 0)
                        if end == 4 + size and size <= self.max_frame:
                            self._end = 0
                            return [bytes(self._view[4:end])]
                    self._parse_frames()
                elif not self._start and self._end >= 5 and not self._ready:
                    # a service response, usually whole in one recv: one unpack, one slice
                    ok, size = _OK_LEN.unpack_from(self._buf, 0)
                    if ok <= 1 and size <= self.max_frame and self._end == 5 + size:
                        self._end = 0
                        return [(bool(ok), bytes(self._view[5:5 + size]))]
                    self._parse()
                else:
                    self._parse()
            except FrameError as exc:
                # the frames before the bad one are still good: they are handed out first
                self._error = exc
        ready = self._ready
        if ready:
            self._ready = []
        return ready

    def frames(self) -> List[Any]:
        """Pop the complete frames parsed so far (``bytes``/``bytearray``, or (ok, payload)).

        Raises FrameError once every good frame before a bad one has been handed out.
        """
        ready = self._ready
        if ready:
            self._ready = []
        elif self._error is not None:
            raise self._error
        return ready

    def pending(self) -> int:
        """Bytes of an incomplete frame held right now."""
        if self._big is not None:
            return self._big_fill
        return self._end - self._start

    def announced(self) -> int | None:
        """The length of the frame being received, once its length prefix is in."""
        if self._big is not None:
            return self._big_len
        prefix = 5 if self.ok_byte else 4
        if self._end - self._start < prefix:
            return None
        return int(_U32.unpack_from(self._buf, self._start + prefix - 4)[0])

    def eof(self) -> None:
        """The peer closed the stream: an error if it stopped in the middle of a frame."""
        if self._error is not None:
            raise self._error
        pending = self.pending()
        if pending:
            raise FrameError(f"connection closed in the middle of a frame ({pending} bytes pending)")

    def feed(self, data: BytesLike) -> List[Any]:
        """Convenience for tests and non-socket users: push ``data`` and return new frames."""
        view = memoryview(data).cast("B")
        while len(view) and self._error is None:
            target = self.recv_buffer()
            n = min(len(target), len(view))
            target[:n] = view[:n]
            view = view[n:]
            self.received(n)
        return self.frames()

    # -- parsing ---------------------------------------------------------------------------

    def _compact(self) -> None:
        start, end = self._start, self._end
        if start:
            self._buf[:end - start] = self._view[start:end]
            self._end = end - start
            self._start = 0
        if self._end == len(self._buf):  # a header that does not fit: must be a big frame
            raise AssertionError("FrameReader invariant violated")  # pragma: no cover

    def _parse_frames(self) -> None:
        """Topic frames (no ok byte): the hot path of every subscriber."""
        buf = self._buf
        view = self._view
        pos = self._start
        end = self._end
        ready = self._ready
        unpack = _U32.unpack_from
        while end - pos >= 4:
            (size,) = unpack(buf, pos)
            stop = pos + 4 + size
            if stop <= end:
                if size > self.max_frame:
                    raise FrameError(f"frame of {size} bytes exceeds the limit of {self.max_frame}")
                ready.append(bytes(view[pos + 4:stop]))
                pos = stop
                continue
            self._start = pos
            self._parse()  # an incomplete frame: the general parser decides where it goes
            return
        if pos == end:
            self._start = self._end = 0
        else:
            self._start = pos
            if len(buf) - pos < 4:
                self._compact()

    def _parse(self) -> None:
        buf = self._buf
        view = self._view
        pos = self._start
        end = self._end
        prefix = 5 if self.ok_byte else 4
        ready = self._ready
        max_frame = self.max_frame
        unpack = _U32.unpack_from
        while end - pos >= prefix:
            if prefix == 5:
                ok = buf[pos]
                if ok > 1:
                    raise FrameError(f"service response ok byte is {ok}, expected 0 or 1")
                (size,) = unpack(buf, pos + 1)
            else:
                ok = 1
                (size,) = unpack(buf, pos)
            if size > max_frame:
                raise FrameError(f"frame of {size} bytes exceeds the limit of {max_frame}")
            body = pos + prefix
            if end - body >= size:
                frame = bytes(view[body:body + size])
                ready.append((bool(ok), frame) if prefix == 5 else frame)
                pos = body + size
                continue
            if prefix + size > len(buf):
                # does not fit the shared buffer: move what we have into its own buffer
                have = end - body
                big = self._spare
                # (never while it waits in _ready: handed out means handed out)
                if big is not None and len(big) == size and not any(f is big for f in ready):
                    self._spare = None
                else:
                    big = bytearray(min(size, max(self.first_chunk, have)))
                big[:have] = view[body:end]
                self._big = big
                self._big_len = size
                self._big_fill = have
                self._big_ok = ok
                self._start = self._end = 0
                return
            if body + size > len(buf):  # fits once moved to the front of the buffer
                self._start = pos
                self._compact()
                return
            break
        if pos == end:
            self._start = self._end = 0
        else:
            self._start = pos
            if pos and len(buf) - pos < prefix:  # keep room for at least a prefix
                self._compact()

    def _finish_big(self) -> None:
        big = self._big
        self._big = None
        if self.reuse_big:
            self._spare = big
        if self.ok_byte:
            self._ready.append((bool(self._big_ok), big))
        else:
            self._ready.append(big)
