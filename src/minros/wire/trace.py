"""The wire trace: what a minros process says and hears on the ROS wire, as JSON lines.

Set ``MINROS_TRACE=FILE`` (or start a program as ``minros trace -o FILE -- COMMAND``) and every
minros process, master, node, tool or launch, appends one JSON object per line to FILE: every
XML-RPC call it makes or serves, every TCPROS connection it opens or accepts with both
connection headers, its message frames, and the close. ``minros trace show`` merges the files
of several processes into the sequence courses teach; ``minros trace pcap`` turns them into a
capture file for Wireshark. The format is documented in ``docs/internals.md`` ("The trace
format"); this docstring is its summary.

Every line has ``t`` (wall-clock seconds, the clock all processes share), ``pid``, ``node``
(the process's ROS name once it has one, else its program name) and ``ev``:

``process``       the first line a process writes: ``argv``, ``host``, ``master`` (its
                  ROS_MASTER_URI), ``format`` (this layout's version), ``minros``.
``node``          the process became a ROS node or the master: ``name``, ``uri``, ``master``.
``xmlrpc.call``   an XML-RPC call this process made; ``xmlrpc.serve`` one it answered. Both
                  carry ``method``, ``args``, then ``reply`` (the value), ``fault`` or
                  ``error`` (the call failed on the network); ``local``/``remote`` (``host:port``),
                  ``n`` (the request's number on its TCP connection), ``t_reply``, and the HTTP
                  bytes themselves as text: ``request``/``response`` with their real lengths
                  ``request_len``/``response_len``.
``tcp.open``      a TCPROS connection: ``conn`` (its number in this process), ``side``
                  (``connect`` or ``accept``), ``local``, ``remote``; ``protocol`` when it is
                  not TCPROS: ``MINROSSHM``, a Unix socket whose addresses are ``@name``.
``tcpros.header`` a connection header, ``dir`` ``out`` (sent) or ``in`` (received), its
                  ``fields`` as ``[key, value]`` pairs in wire order and ``len`` (bytes, the
                  length prefix included).
``tcpros.frame``  a length-prefixed frame: ``dir``, ``n`` (1, 2, ... in that direction),
                  ``off`` (its offset in the byte stream), ``len`` (the length prefix's
                  value), ``head`` (the first bytes of the body in hex), ``ok`` (service
                  responses' status byte), and ``msg``, the decoded message, when
                  ``MINROS_TRACE_MESSAGES=1``. ``topic`` or ``service`` names what it carries.
``tcp.data``      bytes that are not TCPROS (a peer speaking something else): ``len``, ``head``.
``tcpros.segment`` on a MINROSSHM connection, a shared-memory segment announced (its memfd
                  passed with it): ``dir``, ``off``, ``generation``, ``slots``, ``slot_size``.
                  Its messages are ``tcpros.frame`` events whose ``slot`` is
                  ``[generation, slot]`` (the body is in shared memory: no ``head``), or inline
                  ones as over TCPROS; ``tcpros.fallback`` (``reason``) is the publisher giving
                  up on shared memory.
``tcp.eof``       the peer closed its side; ``tcp.close`` this process closed the connection,
                  with the byte and frame counts of both directions.

Bounds: strings in decoded values are cut at 256 characters, lists at 32 items, HTTP bodies
and header values at 64 KiB (each cut value says how much it lost); frames keep
``MINROS_TRACE_BYTES`` bytes (default 64) and only the first ``MINROS_TRACE_FRAMES`` frames of
each connection direction are written (default 1000, ``all`` for no limit; the rest are
counted in ``tcp.close``).

Cost: the XML-RPC server and client test :data:`ON` once per call, and TCPROS sockets are
wrapped when a connection is set up (:func:`watch`) only while tracing is on, so an untraced
process runs exactly the code it ran before. A traced frame costs its thread a tuple (the
frames of a send or recv are cut by a fast path when they come whole); a thread of the writer
formats them and writes them in batches, every FLUSH_INTERVAL seconds (so a reader following
the file sees frames that late), and every other event, written at once, first writes the
frames before it: the lines of one process stay in order. A file that cannot be written costs
one line on stderr and the process runs on untraced.
"""

from __future__ import annotations

import atexit
import base64
import collections
import json
import math
import os
import socket
import struct
import sys
import threading
import time
import xmlrpc.client
from typing import Any, Callable, Deque, Dict, List, Optional, Tuple

from minros import rosenv
from minros.msgs.tval import TVal
from minros.wire import tcpros

__all__ = [
    "ENV_BYTES",
    "ENV_FILE",
    "ENV_FRAMES",
    "ENV_MESSAGES",
    "FORMAT",
    "ON",
    "TracedSocket",
    "address",
    "event",
    "plain",
    "set_node",
    "start",
    "stop",
    "watch",
    "xmlrpc_called",
    "xmlrpc_served",
]

ENV_FILE = "MINROS_TRACE"
ENV_MESSAGES = "MINROS_TRACE_MESSAGES"
ENV_FRAMES = "MINROS_TRACE_FRAMES"
ENV_BYTES = "MINROS_TRACE_BYTES"
#: the layout version written in every ``process`` line
FORMAT = 1

DEFAULT_FRAMES = 1000
DEFAULT_BYTES = 64
#: frame events are written in batches: every this many seconds, or once this many wait;
#: past MAX_PENDING the thread recording one writes them itself
FLUSH_INTERVAL = 0.2
FLUSH_AT = 2048
MAX_PENDING = 1 << 16
#: HTTP texts and connection header values longer than this are cut
RAW_LIMIT = 64 << 10
#: a frame up to this size is decoded when messages are asked for
DECODE_LIMIT = 64 << 10
STR_LIMIT = 256
LIST_LIMIT = 32
DEPTH_LIMIT = 8

#: True while this process writes a trace (read it as ``trace.ON``: it changes)
ON = False

_U32 = struct.Struct("<I")
_now = time.time


# --------------------------------------------------------------------------- plain values


def _cut_text(text: str, limit: int = STR_LIMIT) -> str:
    if len(text) <= limit:
        return text
    return f"{text[:limit]}…(+{len(text) - limit} chars)"


def _cut_hex(data: Any, limit: int) -> str:
    raw = bytes(data[:limit])
    text = raw.hex()
    if len(data) > limit:
        text += f"…(+{len(data) - limit} bytes)"
    return text


def plain(value: Any, depth: int = 0) -> Any:
    """``value`` (an XML-RPC value or a message) as JSON data, large parts abbreviated: long
    strings and lists are cut with a note of what is missing, bytes become hex, messages
    dicts of their fields, times ``{"secs", "nsecs"}``."""
    if value is None or isinstance(value, (bool, int)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if isinstance(value, str):
        return _cut_text(value)
    if depth >= DEPTH_LIMIT:
        return "…"
    if isinstance(value, (bytes, bytearray, memoryview)):
        return {"hex": _cut_hex(memoryview(value).cast("B"), 32), "len": memoryview(value).nbytes}
    if isinstance(value, xmlrpc.client.Binary):
        data = value.data
        return {"base64": _cut_text(base64.b64encode(data[:192]).decode()), "len": len(data)}
    if isinstance(value, dict):
        out: Dict[str, Any] = {}
        for i, (key, item) in enumerate(value.items()):
            if i == LIST_LIMIT:
                out["…"] = f"+{len(value) - LIST_LIMIT} keys"
                break
            out[str(key)] = plain(item, depth + 1)
        return out
    if isinstance(value, (list, tuple)):
        items = [plain(item, depth + 1) for item in value[:LIST_LIMIT]]
        if len(value) > LIST_LIMIT:
            items.append(f"…(+{len(value) - LIST_LIMIT} items)")
        return items
    if isinstance(value, TVal):  # genpy Time/Duration
        return {"secs": value.secs, "nsecs": value.nsecs}
    slots = getattr(value, "__slots__", None)
    if slots is not None and hasattr(value, "_slot_types"):  # a message
        return {name: plain(getattr(value, name, None), depth + 1) for name in slots}
    tolist = getattr(value, "tolist", None)  # numpy arrays (numpy_msg)
    if tolist is not None:
        if getattr(value, "dtype", None) is not None and value.dtype.itemsize == 1:
            return {"hex": _cut_hex(memoryview(value.tobytes()), 32), "len": int(value.size)}
        if getattr(value, "ndim", 1) != 1:
            return f"array of shape {tuple(value.shape)}"
        items = plain(value[:LIST_LIMIT].tolist(), depth)
        if value.size > LIST_LIMIT:
            items.append(f"…(+{value.size - LIST_LIMIT} items)")
        return items
    return _cut_text(repr(value))


def address(addr: Any) -> str:
    """``host:port`` (``[v6]:port``) of a socket address; ``@name`` for an abstract Unix one."""
    if isinstance(addr, bytes):
        addr = addr.decode("utf-8", "replace")
    if isinstance(addr, str):
        return "@" + addr[1:] if addr.startswith("\0") else addr or "(unnamed)"
    try:
        host, port = addr[0], addr[1]
    except (TypeError, IndexError):
        return str(addr)
    return f"[{host}]:{port}" if ":" in str(host) else f"{host}:{port}"


def _raw_text(data: bytes) -> Tuple[str, int]:
    """HTTP bytes as text for the trace: (the first RAW_LIMIT bytes, the real length)."""
    size = len(data)
    if size > RAW_LIMIT:
        data = data[:RAW_LIMIT]
        # a multi-byte character cut at the limit is left out whole
        return data.decode("utf-8", "ignore"), size
    try:
        return data.decode("utf-8"), size
    except UnicodeDecodeError:
        return data.decode("latin-1"), size


# --------------------------------------------------------------------------- the writer


class _Writer:
    """Owns the trace file of this process (opened for appending, so the lines of several
    processes sharing it never mix: every write is whole lines).

    Frame events, the many, are recorded as tuples on the hot path (:meth:`queue`: one
    append) and written as JSON lines in batches by a thread of their own, every
    FLUSH_INTERVAL seconds or as soon as FLUSH_AT are waiting; every other event is written
    at once, after the frames recorded before it, so the file keeps the order of events.
    ``stop()`` and the end of the process write what is left."""

    def __init__(self, path: str, fd: int) -> None:
        self.path = path
        self.fd = fd
        self.lock = threading.Lock()
        self.pid = os.getpid()
        self.node = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "python"
        self.conn_ids = iter(range(1, 1 << 62))
        self.messages = os.environ.get(ENV_MESSAGES, "") not in ("", "0")
        frames = os.environ.get(ENV_FRAMES, "")
        self.frame_limit = -1 if frames == "all" else _int(frames, DEFAULT_FRAMES)
        self.head_bytes = max(0, _int(os.environ.get(ENV_BYTES, ""), DEFAULT_BYTES))
        #: frame events not written yet: (tap, t, n, off, len, head, ok)
        self.pending: Deque[Tuple[Any, ...]] = collections.deque()
        self.wake = threading.Event()
        self.flusher = threading.Thread(target=self._flush_loop, daemon=True,
                                        name="minros-trace-writer")
        self.flusher.start()

    def queue(self, item: Tuple[Any, ...]) -> None:
        """Record one frame event (the hot path: no formatting, no system call)."""
        pending = self.pending
        pending.append(item)
        size = len(pending)
        if size == FLUSH_AT:
            self.wake.set()
        elif size > MAX_PENDING:  # the writer thread cannot keep up: write them here
            self.flush()

    def write(self, fields: Dict[str, Any]) -> None:
        """Write one event now (after the frame events recorded before it)."""
        line = json.dumps(fields, ensure_ascii=False, separators=(",", ":"), default=str)
        with self.lock:
            lines = self._pending_lines()
            lines.append(line)
            self._write(lines)

    def flush(self) -> None:
        """Write the frame events recorded so far."""
        with self.lock:
            lines = self._pending_lines()
            if lines:
                self._write(lines)

    def _pending_lines(self) -> List[str]:
        """The recorded frame events as lines, taken off the queue (lock held)."""
        pending = self.pending
        lines: List[str] = []
        append = lines.append
        node = self.node
        templates: Dict[Any, Tuple[str, str]] = {}
        last_t = None
        stamp = ""
        for _ in range(len(pending)):
            tap, t, n, off, size, head, ok = pending.popleft()
            if t != last_t:  # the frames of one recv or send share it
                last_t = t
                stamp = f'{{"t":{t:.6f},'
            template = templates.get(tap)
            if template is None:
                template = templates[tap] = tap.frame_line(node)
            if ok < 0:
                append(stamp + template[0] % (n, off, size, head.hex()))
            else:
                append(stamp + template[1] % (n, off, size, head.hex(), ok))
        return lines

    def _write(self, lines: List[str]) -> None:
        if self.fd < 0:
            return
        lines.append("")
        data = "\n".join(lines).encode("utf-8", "backslashreplace")
        try:
            while data:  # one write of whole lines, unless the disk takes less
                data = data[os.write(self.fd, data):]
        except OSError as exc:
            _fail(f"cannot write the trace to {self.path}: {exc.strerror or exc}; "
                  "going on without a trace")
            self.fd = -1

    def _flush_loop(self) -> None:
        while self.fd >= 0:
            self.wake.wait(FLUSH_INTERVAL)
            self.wake.clear()
            if self.pending:
                self.flush()


def _int(text: str, default: int) -> int:
    try:
        return int(text)
    except ValueError:
        return default


_writer: Optional[_Writer] = None


def _fail(text: str) -> None:
    global ON
    ON = False
    # children would try again and say the same: they start untraced
    os.environ.pop(ENV_FILE, None)
    try:
        sys.stderr.write(f"minros: {text}\n")
        sys.stderr.flush()
    except (OSError, ValueError):
        pass


def start(path: str) -> bool:
    """Trace this process to ``path`` (appending). False, after one line on stderr, when the
    file cannot be opened for writing."""
    global _writer, ON
    stop()
    try:
        fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_CLOEXEC", 0),
                     0o644)
    except OSError as exc:
        _fail(f"cannot write the trace to {path}: {exc.strerror or exc}; running without a "
              f"trace (set {ENV_FILE} to a file this process may create or append to)")
        return False
    _writer = _Writer(path, fd)
    ON = True
    event("process", argv=list(sys.argv), host=socket.gethostname(),
          master=os.environ.get("ROS_MASTER_URI", rosenv.DEFAULT_MASTER_URI), format=FORMAT,
          minros=_version(), messages=_writer.messages)
    return True


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("minros")
    except Exception:  # noqa: BLE001 - a source checkout without metadata
        return "unknown"


def stop() -> None:
    """Stop tracing (the file is closed)."""
    global _writer, ON
    ON = False
    writer, _writer = _writer, None
    if writer is not None:
        writer.flush()
        with writer.lock:
            fd, writer.fd = writer.fd, -1
        writer.wake.set()  # its thread ends
        if fd >= 0:
            os.close(fd)


def flush() -> None:
    """Write the frame events recorded so far (they are written in batches, every
    FLUSH_INTERVAL seconds; every other event is written at once)."""
    writer = _writer
    if writer is not None:
        writer.flush()


atexit.register(flush)


def set_node(name: str, uri: str = "", master: str = "") -> None:
    """This process is now ROS node (or master) ``name``: later lines carry the name, and one
    ``node`` line ties the name to its XML-RPC URI."""
    writer = _writer
    if writer is None:
        return
    writer.node = name
    event("node", name=name, uri=uri, master=master)


def event(kind: str, **fields: Any) -> None:
    """Write one event (nothing when tracing is off)."""
    writer = _writer
    if writer is None:
        return
    line = {"t": round(time.time(), 6), "pid": writer.pid, "node": writer.node, "ev": kind}
    line.update(fields)
    writer.write(line)


def _event_at(t: float, kind: str, fields: Dict[str, Any]) -> None:
    writer = _writer
    if writer is None:
        return
    line = {"t": round(t, 6), "pid": writer.pid, "node": writer.node, "ev": kind}
    line.update(fields)
    writer.write(line)


# --------------------------------------------------------------------------- XML-RPC


def _xmlrpc_fields(method: str, args: Any, request: bytes, response: Optional[bytes],
                   result: Any, error: Optional[BaseException]) -> Dict[str, Any]:
    fields: Dict[str, Any] = {"method": method, "args": plain(list(args))}
    if error is not None:
        if isinstance(error, xmlrpc.client.Fault):
            fields["fault"] = _cut_text(f"{error.faultCode}: {error.faultString}")
        else:
            fields["error"] = _cut_text(f"{type(error).__name__}: {error}")
    else:
        fields["reply"] = plain(result)
    fields["request"], fields["request_len"] = _raw_text(request)
    if response is not None:
        fields["response"], fields["response_len"] = _raw_text(response)
    return fields


def xmlrpc_called(uri: str, method: str, args: Any, n: int, addresses: Optional[Tuple[str, str]],
                  t0: float, request: bytes, response: Optional[bytes], result: Any = None,
                  error: Optional[BaseException] = None) -> None:
    """The client side of one XML-RPC call (``request``/``response``: the HTTP bytes)."""
    if _writer is None:
        return
    fields: Dict[str, Any] = {"uri": uri}
    if addresses is not None:
        fields["local"], fields["remote"] = addresses
        fields["n"] = n
    fields.update(_xmlrpc_fields(method, args, request, response, result, error))
    fields["t_reply"] = round(time.time(), 6)
    _event_at(t0, "xmlrpc.call", fields)


def xmlrpc_served(addresses: Tuple[str, str], n: int, t0: float, request: bytes, body: bytes,
                  response: bytes, reply: bytes) -> None:
    """The server side of one XML-RPC call: ``request`` the whole HTTP request, ``body`` its
    body, ``response`` the whole HTTP response and ``reply`` its body (decoded here, so the
    server pays for it only when tracing)."""
    if _writer is None:
        return
    method: Optional[str] = "?"
    args: Any = []
    result: Any = None
    error: Optional[BaseException] = None
    try:
        args, method = xmlrpc.client.loads(body, use_builtin_types=False)
        (result,), _ = xmlrpc.client.loads(reply, use_builtin_types=False)
    except xmlrpc.client.Fault as fault:
        error = fault
    except Exception as exc:  # noqa: BLE001 - a body the server refused: traced as such
        error = exc
    fields: Dict[str, Any] = {"local": addresses[0], "remote": addresses[1], "n": n}
    fields.update(_xmlrpc_fields(method or "?", args, request, response, result, error))
    fields["t_reply"] = round(time.time(), 6)
    _event_at(t0, "xmlrpc.serve", fields)


# --------------------------------------------------------------------------- TCPROS


def watch(sock: socket.socket, side: str, protocol: str = "TCPROS") -> Any:
    """``sock`` itself when tracing is off, else a :class:`TracedSocket` around it. Called once
    per TCPROS connection, where it is set up (``side``: ``connect`` or ``accept``), and per
    MINROSSHM one (``protocol``)."""
    writer = _writer
    if writer is None:
        return sock
    return TracedSocket(sock, side, writer, protocol)


class _Connection:
    """What the two directions of one traced connection share."""

    __slots__ = ("id", "side", "kind", "name", "header_out", "header_in", "writer", "decoders",
                 "closed", "records")

    def __init__(self, side: str, writer: _Writer, protocol: str = "TCPROS") -> None:
        self.id = next(writer.conn_ids)
        self.side = side
        #: after the headers: MINROSSHM's records, not TCPROS frames
        self.records = protocol == "MINROSSHM"
        self.kind = ""  # "topic", "service" or "probe", once the client's header is seen
        self.name = ""  # the topic or service
        self.header_out: Dict[str, str] = {}
        self.header_in: Dict[str, str] = {}
        self.writer = writer
        self.decoders: Dict[str, Any] = {}
        self.closed = False

    def learn(self, direction: str, fields: Dict[str, str]) -> None:
        if direction == "out":
            self.header_out = fields
        else:
            self.header_in = fields
        client = self.header_out if self.side == "connect" else self.header_in
        if client and not self.kind:
            if "topic" in client:
                self.kind, self.name = "topic", client["topic"]
            elif "service" in client:
                self.kind = "probe" if client.get("probe") == "1" else "service"
                self.name = client["service"]

    def ok_byte(self, direction: str) -> bool:
        """Service responses (server -> client) start with a status byte."""
        return self.kind == "service" and (direction == "in") == (self.side == "connect")

    def decoder(self, direction: str) -> Optional[Callable[[bytes], Any]]:
        """A function decoding this direction's frames, from the headers (None: cannot)."""
        found = self.decoders.get(direction, False)
        if found is not False:
            known: Optional[Callable[[bytes], Any]] = found
            return known
        decode = None
        try:
            server = self.header_in if self.side == "connect" else self.header_out
            if self.kind == "topic" and server.get("type") and server.get("message_definition"):
                from minros.msgs import generate_dynamic

                cls = generate_dynamic(server["type"], server["message_definition"])[server["type"]]
                decode = _decode_with(cls)
            elif self.kind == "service" and server.get("type"):
                from minros.msgs import get_service_class

                srv = get_service_class(server["type"])
                requests = (direction == "out") == (self.side == "connect")
                decode = _decode_with(srv._request_class if requests else srv._response_class)
        except Exception:  # noqa: BLE001 - a type this process cannot build: bytes only
            decode = None
        self.decoders[direction] = decode
        return decode

    def base(self) -> Dict[str, Any]:
        fields: Dict[str, Any] = {"conn": self.id}
        if self.kind:
            fields["topic" if self.kind == "topic" else "service"] = self.name
        return fields


def _decode_with(cls: Any) -> Callable[[bytes], Any]:
    def decode(data: bytes) -> Any:
        return plain(cls().deserialize(data))
    return decode


class _Tap:
    """One direction of a traced connection: a sans-IO reader that finds the connection
    header and then the frames in the bytes as they go by, and writes their events."""

    __slots__ = ("conn", "dir", "offset", "state", "part", "need", "start", "t_start", "size",
                 "left", "head", "body", "ok", "frames", "traced", "limit", "head_bytes",
                 "writer", "_fields", "_fields_key")

    HEADER, PREFIX, BODY, OPAQUE, RECORD = range(5)

    def __init__(self, conn: _Connection, direction: str) -> None:
        self.conn = conn
        self.dir = direction
        self.offset = 0  # bytes seen so far
        self.state = self.HEADER
        self.part = bytearray()  # a length prefix or a header being collected
        self.need = 4
        self.start = 0  # stream offset of the current header or frame
        self.t_start = 0.0
        self.size = 0
        self.left = 0
        self.head = bytearray()
        self.body: Optional[bytearray] = None
        self.ok = -1
        self.frames = 0
        self.traced = 0
        self.writer = conn.writer
        self.limit = conn.writer.frame_limit
        self.head_bytes = conn.writer.head_bytes
        self._fields: Tuple[str, str] = ("", "")
        self._fields_key: Any = None

    def frame_line(self, node: str) -> Tuple[str, str]:
        """The %-templates of this direction's frame events after ``t`` (without and with the
        ok byte): what they all share made once, as JSON text (the writer formats many)."""
        key = (node, self.conn.kind)
        if key != self._fields_key:
            fields: Dict[str, Any] = {"pid": self.writer.pid, "node": node, "ev": "tcpros.frame"}
            fields.update(self.conn.base())
            fields["dir"] = self.dir
            shared = json.dumps(fields, ensure_ascii=False, separators=(",", ":"),
                                default=str)[1:-1].replace("%", "%%")
            line = shared + ',"n":%d,"off":%d,"len":%d,"head":"%s"'
            self._fields = (line + "}", line + ',"ok":%d}')
            self._fields_key = key
        return self._fields

    def feed(self, data: Any, t: float) -> None:
        """``data`` went by at time ``t``: bytes, or a memoryview of bytes."""
        if self.state == self.PREFIX and not self.part and not self.writer.messages:
            # The usual case, whole frames, read here: one tuple each for the writer
            end = len(data)
            pos = 0
            need = self.need
            while end - pos >= need:
                if need == 5:
                    ok = data[pos]
                    (size,) = _U32.unpack_from(data, pos + 1)
                else:
                    ok = -1
                    (size,) = _U32.unpack_from(data, pos)
                body = pos + need
                stop = body + size
                if stop > end:
                    break
                self.frames += 1
                if self.limit < 0 or self.traced < self.limit:
                    self.traced += 1
                    self.writer.queue((self, t, self.frames, self.offset + pos, size,
                                       bytes(data[body:min(stop, body + self.head_bytes)]), ok))
                pos = stop
            if pos:
                self.offset += pos
                if pos == end:
                    return
                data = data[pos:]
        view = memoryview(data).cast("B") if not isinstance(data, bytes) else data
        pos, end = 0, len(view)
        while pos < end:
            state = self.state
            if state == self.BODY:
                take = min(self.left, end - pos)
                if len(self.head) < self.head_bytes:
                    self.head += view[pos:pos + min(take, self.head_bytes - len(self.head))]
                if self.body is not None:
                    self.body += view[pos:pos + take]
                pos += take
                self.left -= take
                if not self.left:
                    self._frame_done(t)
                continue
            if state == self.OPAQUE:
                self._flush_opaque(view[pos:end], self.offset + pos, t)
                pos = end
                continue
            take = min(self.need - len(self.part), end - pos)
            if not self.part:
                self.start = self.offset + pos
                self.t_start = t
            self.part += view[pos:pos + take]
            pos += take
            if len(self.part) == self.need:
                self._part_done(t)
        if self.state == self.OPAQUE and self.part:
            self._flush_opaque(b"", self.offset + end, t)
        self.offset += end

    def _part_done(self, t: float) -> None:
        part = self.part
        if self.state == self.HEADER:
            if self.need == 4:  # the header's length prefix
                (size,) = _U32.unpack_from(part, 0)
                if size > tcpros.DEFAULT_MAX_HEADER:
                    self._to_opaque(t)
                    return
                self.need = 4 + size
                if size:
                    return
            try:
                fields = tcpros.decode_header(memoryview(part)[4:])
            except tcpros.HeaderError:
                self._to_opaque(t)
                return
            self.conn.learn(self.dir, fields)
            pairs = [[key, value if len(value) <= RAW_LIMIT else _cut_text(value, RAW_LIMIT)]
                     for key, value in fields.items()]
            base = self.conn.base()
            base.update(dir=self.dir, off=self.start, len=len(part), fields=pairs)
            _event_at(self.t_start if self.dir == "out" else t, "tcpros.header", base)
            self._next_frame()
            return
        if self.state == self.RECORD:
            self._record_done(t)
            return
        # a frame's prefix
        if len(part) == 5:
            self.ok = part[0]
            (self.size,) = _U32.unpack_from(part, 1)
        else:
            self.ok = -1
            (self.size,) = _U32.unpack_from(part, 0)
        self.left = self.size
        self.head = bytearray()
        decode = (self.conn.writer.messages and self.size <= DECODE_LIMIT
                  and (self.limit < 0 or self.traced < self.limit))
        self.body = bytearray() if decode else None
        self.state = self.BODY
        if not self.size:
            self._frame_done(t)

    def _next_frame(self) -> None:
        self.part = bytearray()
        if self.conn.records:
            self.state = self.RECORD
            self.need = 4  # the tag
            return
        self.state = self.PREFIX
        self.need = 5 if self.conn.ok_byte(self.dir) else 4

    #: MINROSSHM records (minros.wire.shm): tag -> the record's size, or its head's
    _RECORDS = {b"SLOT": 28, b"SEGM": 24, b"DONE": 12, b"MSG ": 8, b"FALL": 8}

    def _record_done(self, t: float) -> None:
        """A MINROSSHM record's tag, head or whole (``part``) is in."""
        part = self.part
        tag = bytes(part[:4])
        size = self._RECORDS.get(tag)
        if size is None:
            self._to_opaque(t)
            return
        if len(part) < size:
            self.need = size
            return
        if tag == b"MSG ":  # an inline message: its frame follows, as over TCPROS
            self.part = part[4:]
            self.state = self.PREFIX
            self.start += 4
            self._part_done(t)
            return
        if tag == b"FALL":
            (length,) = _U32.unpack_from(part, 4)
            if len(part) < 8 + min(length, 1024):
                self.need = 8 + min(length, 1024)
                return
        when = self.t_start if self.dir == "out" else t
        fields = self.conn.base()
        fields.update(dir=self.dir, off=self.start)
        if tag == b"SLOT":
            generation, index, _offset, length, _seq = struct.unpack_from("<IIIIQ", part, 4)
            self.frames += 1
            if self.limit < 0 or self.traced < self.limit:
                self.traced += 1
                fields.update(n=self.frames, len=max(length - 4, 0), head="",
                              slot=[generation, index])
                _event_at(when, "tcpros.frame", fields)
        elif tag == b"SEGM":
            generation, slots, slot_size, _size = struct.unpack_from("<IIIQ", part, 4)
            fields.update(generation=generation, slots=slots, slot_size=slot_size)
            _event_at(when, "tcpros.segment", fields)
        elif tag == b"FALL":
            fields.update(reason=bytes(part[8:]).decode("utf-8", "replace"))
            _event_at(when, "tcpros.fallback", fields)
        self._next_frame()  # DONE records (slots given back) are not written

    def _frame_done(self, t: float) -> None:
        self.frames += 1
        if (self.limit < 0 or self.traced < self.limit) and self.body is None:
            self.traced += 1
            self.writer.queue((self, self.t_start if self.dir == "out" else t, self.frames,
                               self.start, self.size, bytes(self.head), self.ok))
        elif self.limit < 0 or self.traced < self.limit:
            self.traced += 1
            fields = self.conn.base()
            fields.update(dir=self.dir, n=self.frames, off=self.start, len=self.size,
                          head=bytes(self.head).hex())
            if self.ok >= 0:
                fields["ok"] = self.ok
            if self.body is not None:
                fields["msg"] = self._decode(bytes(self.body))
            _event_at(self.t_start if self.dir == "out" else t, "tcpros.frame", fields)
        self.body = None
        self._next_frame()

    def _decode(self, body: bytes) -> Any:
        if self.ok == 0:  # a service's error text
            return body.decode("utf-8", "replace")
        decode = self.conn.decoder(self.dir)
        if decode is None:
            return None
        try:
            return decode(body)
        except Exception as exc:  # noqa: BLE001 - the receiver will say the same, louder
            return {"error": _cut_text(f"cannot decode: {exc}")}

    def _to_opaque(self, t: float) -> None:
        """Not TCPROS after all: the rest of this direction is traced as plain bytes (the
        bytes read so far go out with the next ones)."""
        self.state = self.OPAQUE

    def _flush_opaque(self, rest: Any, off: int, t: float) -> None:
        if self.part:
            data, off = bytes(self.part) + bytes(rest), self.start
            self.part = bytearray()
        else:
            data = bytes(rest)
        self._opaque(data, off, t)

    def _opaque(self, data: bytes, off: int, t: float) -> None:
        self.frames += 1
        if self.limit < 0 or self.traced < self.limit:
            self.traced += 1
            fields = self.conn.base()
            fields.update(dir=self.dir, off=off, len=len(data),
                          head=data[:max(self.head_bytes, 16)].hex())
            _event_at(t, "tcp.data", fields)


class TracedSocket:
    """A TCPROS socket that traces what it sends and receives; everything else is the
    socket's own (``fileno``, ``settimeout``, ``getsockname``, ...)."""

    def __init__(self, sock: socket.socket, side: str, writer: _Writer,
                 protocol: str = "TCPROS") -> None:
        self._sock = sock
        self._conn = conn = _Connection(side, writer, protocol)
        self._out = _Tap(conn, "out")
        self._in = _Tap(conn, "in")
        try:
            self._addresses = (address(sock.getsockname()), address(sock.getpeername()))
        except OSError:
            self._addresses = ("?", "?")
        opened = {"conn": conn.id, "side": side, "local": self._addresses[0],
                  "remote": self._addresses[1]}
        if protocol != "TCPROS":
            opened["protocol"] = protocol
        _event_at(time.time(), "tcp.open", opened)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._sock, name)

    def __enter__(self) -> TracedSocket:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<traced {self._sock!r}>"

    # -- sending

    def send(self, data: Any, flags: int = 0) -> int:
        t = _now()
        sent = self._sock.send(data, flags)
        if sent:
            if data.__class__ is bytes and sent == len(data):
                self._out.feed(data, t)
            else:
                self._out.feed(memoryview(data).cast("B")[:sent], t)
        return sent

    def sendall(self, data: Any, flags: int = 0) -> None:
        t = time.time()
        self._sock.sendall(data, flags)
        self._out.feed(data, t)

    def sendmsg(self, buffers: Any, *args: Any) -> int:
        buffers = list(buffers)
        t = time.time()
        sent = self._sock.sendmsg(buffers, *args)
        left = sent
        for buf in buffers:
            if left <= 0:
                break
            view = memoryview(buf).cast("B")
            self._out.feed(view[:left], t)
            left -= len(view)
        return sent

    # -- receiving

    def recv(self, size: int, flags: int = 0) -> bytes:
        data = self._sock.recv(size, flags)
        if data:
            self._in.feed(data, _now())
        elif size:
            self._eof()
        return data

    def recv_into(self, buffer: Any, size: int = 0, flags: int = 0) -> int:
        n = self._sock.recv_into(buffer, size, flags)
        if n:
            self._in.feed(memoryview(buffer).cast("B")[:n], _now())
        elif size or len(memoryview(buffer)):
            self._eof()
        return n

    def recvmsg_into(self, buffers: Any, *args: Any) -> Any:
        buffers = list(buffers)
        result = self._sock.recvmsg_into(buffers, *args)
        left = result[0]
        if not left:
            self._eof()
        t = time.time()
        for buf in buffers:
            if left <= 0:
                break
            view = memoryview(buf).cast("B")
            self._in.feed(view[:left], t)
            left -= len(view)
        return result

    # -- the end

    def _eof(self) -> None:
        if not self._conn.closed:
            event("tcp.eof", conn=self._conn.id, received=self._in.offset)

    def _closing(self) -> None:
        conn = self._conn
        if conn.closed:
            return
        conn.closed = True
        fields = conn.base()
        fields.update(local=self._addresses[0], remote=self._addresses[1],
                      sent=self._out.offset, received=self._in.offset,
                      frames_out=self._out.frames, frames_in=self._in.frames,
                      untraced_out=self._out.frames - self._out.traced,
                      untraced_in=self._in.frames - self._in.traced)
        event("tcp.close", **fields)

    def shutdown(self, how: int) -> None:
        self._closing()
        self._sock.shutdown(how)

    def close(self) -> None:
        self._closing()
        self._sock.close()


# --------------------------------------------------------------------------- on import

if os.environ.get(ENV_FILE):
    start(os.environ[ENV_FILE])
