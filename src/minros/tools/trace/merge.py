"""Trace files in; processes, runs and one item per exchange on the wire out.

A process writes its own view of the wire: the XML-RPC calls it made and served, the bytes of
its TCPROS connections. When both ends of an exchange were traced, the exchange is in two
files (or twice in one); :class:`Merger` joins the views (an XML-RPC exchange by its client and
server addresses and its number on that connection, a header or frame by its connection and
stream offset) and names every end after the node it is, from what the trace itself says:
``node`` lines, registration arguments, ``requestTopic`` answers and the ``callerid`` of
connection headers.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, Optional, Tuple
from urllib.parse import urlparse

__all__ = [
    "Call",
    "Connection",
    "Follower",
    "Merger",
    "Names",
    "Process",
    "Run",
    "TraceError",
    "TraceFile",
    "Wire",
    "load",
    "merge",
    "split_runs",
]

#: master methods about one topic, and about one service (their second argument names it)
TOPIC_METHODS = ("registerPublisher", "unregisterPublisher", "registerSubscriber",
                 "unregisterSubscriber", "publisherUpdate", "requestTopic")
SERVICE_METHODS = ("registerService", "unregisterService", "lookupService")
DEFAULT_MASTER_PORT = 11311
#: bytes of a frame's body a live view (a Merger with a limit) keeps
LIVE_HEAD = 128


class TraceError(Exception):
    """A file that cannot be read as a trace at all (one line for the user)."""


# --------------------------------------------------------------------------- files


@dataclass
class Process:
    """One traced process, from its ``process`` line on."""

    pid: int
    path: str
    argv: List[str] = field(default_factory=list)
    host: str = ""
    master: str = ""
    name: str = ""
    uri: str = ""
    first: float = 0.0
    last: float = 0.0
    messages: bool = False

    @property
    def master_port(self) -> int:
        try:
            return urlparse(self.master).port or DEFAULT_MASTER_PORT
        except ValueError:
            return DEFAULT_MASTER_PORT

    def program(self) -> str:
        if not self.argv:
            return "?"
        return " ".join([os.path.basename(self.argv[0]), *self.argv[1:]])


@dataclass
class TraceFile:
    path: str
    events: List[Dict[str, Any]]
    processes: List[Process]
    #: why reading stopped before the end of the file (None: it was read whole)
    stop: Optional[str] = None


def _is_event(value: Any) -> bool:
    return isinstance(value, dict) and isinstance(value.get("ev"), str) and isinstance(
        value.get("t"), (int, float)) and isinstance(value.get("pid"), int)


class _Attributor:
    """Gives each event of one file its Process (a pid is a process from its ``process``
    line until the next one with the same pid)."""

    def __init__(self, path: str) -> None:
        self.path = path
        self.current: Dict[int, Process] = {}
        self.processes: List[Process] = []

    def take(self, ev: Dict[str, Any]) -> None:
        pid = ev["pid"]
        proc = self.current.get(pid)
        if ev["ev"] == "process" or proc is None:
            proc = Process(pid=pid, path=self.path, first=ev["t"], last=ev["t"],
                           name=str(ev.get("node", "")))
            self.current[pid] = proc
            self.processes.append(proc)
        if ev["ev"] == "process":
            argv = ev.get("argv")
            proc.argv = [str(arg) for arg in argv] if isinstance(argv, list) else []
            proc.host = str(ev.get("host", ""))
            proc.master = str(ev.get("master", ""))
            proc.messages = bool(ev.get("messages"))
        elif ev["ev"] == "node":
            proc.name = str(ev.get("name", proc.name))
            proc.uri = str(ev.get("uri", ""))
            if ev.get("master"):
                proc.master = str(ev["master"])
        proc.first = min(proc.first, ev["t"])
        t_reply = ev.get("t_reply")
        proc.last = max(proc.last, t_reply if isinstance(t_reply, (int, float)) else ev["t"])
        ev["_p"] = proc


def _parse(raw: bytes) -> Tuple[Optional[Dict[str, Any]], str]:
    """One line of a trace file: (the event, "") or (None, what is wrong with it)."""
    if not raw.endswith(b"\n"):
        return None, "the line is cut off (the file ends in the middle of an event)"
    try:
        ev = json.loads(raw)
    except ValueError:
        return None, "the line is not JSON"
    if not _is_event(ev):
        return None, "the line is not a trace event"
    return ev, ""


def _not_a_trace(path: str, number: int, problem: str) -> str:
    return (f"{path} is not a minros trace: line {number}: {problem} (a trace is written by "
            "MINROS_TRACE=FILE or 'minros trace -o FILE -- COMMAND')")


def load(path: str) -> TraceFile:
    """Read a trace file up to its end, or up to the first line that is not a whole trace
    event (a file cut while being written or copied): ``stop`` then says where and why."""
    try:
        handle = open(path, "rb")
    except OSError as exc:
        raise TraceError(f"cannot read {path}: {exc.strerror or exc}") from None
    events: List[Dict[str, Any]] = []
    who = _Attributor(path)
    stop = None
    offset = 0
    with handle:
        for number, raw in enumerate(handle, 1):
            ev, problem = _parse(raw)
            if ev is None:
                if not events:
                    raise TraceError(_not_a_trace(path, number, problem))
                stop = (f"{path} stops at line {number} (byte {offset}): {problem}; "
                        f"read the {len(events)} events before it")
                break
            who.take(ev)
            events.append(ev)
            offset += len(raw)
    if not events and stop is None:
        raise TraceError(f"{path} is empty: no process wrote to it (is MINROS_TRACE set in the "
                         "environment of the program?)")
    return TraceFile(path, events, who.processes, stop)


class Follower:
    """New events of growing trace files (``show --follow``, ``minros web --trace``): whole
    lines only, so a line being written is read once it is complete. A file that does not
    exist yet is waited for (``waiting`` says why it is not read); one that shrinks
    (``minros trace -o`` overwrites its file when it starts again) is read again from its
    start; at a line that is not a trace event, following that file stops (``bad`` says
    where)."""

    #: bytes read from one file in one poll
    CHUNK = 1 << 20

    def __init__(self, paths: Iterable[str] = ()) -> None:
        self.paths: List[str] = []
        self.offsets: Dict[str, int] = {}
        self.partial: Dict[str, bytes] = {}
        self.who: Dict[str, _Attributor] = {}
        self.lines: Dict[str, int] = {}  # whole lines read
        self.line_end: Dict[str, int] = {}  # byte offset after the last whole line
        self.bad: Dict[str, str] = {}
        self.waiting: Dict[str, str] = {}
        self.restarts: Dict[str, int] = {}
        #: the last poll left bytes unread (a file grew by more than CHUNK): poll again soon
        self.behind = False
        for path in paths:
            self.add(path)

    def add(self, path: str) -> None:
        """Follow one more file (from its start)."""
        if path not in self.offsets:
            self.paths.append(path)
            self._start(path)

    def _start(self, path: str) -> None:
        self.offsets[path] = self.lines[path] = self.line_end[path] = 0
        self.partial[path] = b""
        self.who[path] = _Attributor(path)

    def poll(self) -> List[Dict[str, Any]]:
        """Events appended since the last poll, in time order."""
        out: List[Dict[str, Any]] = []
        self.behind = False
        for path in self.paths:
            if path in self.bad:
                continue
            try:
                with open(path, "rb") as handle:
                    if os.fstat(handle.fileno()).st_size < self.offsets[path]:
                        self._start(path)  # overwritten: a new trace in the same file
                        self.restarts[path] = self.restarts.get(path, 0) + 1
                    handle.seek(self.offsets[path])
                    data = handle.read(self.CHUNK)
            except OSError as exc:
                self.waiting[path] = ("does not exist (yet)" if isinstance(exc, FileNotFoundError)
                                      else f"cannot be read: {exc.strerror or exc}")
                continue
            self.waiting.pop(path, None)
            if not data:
                continue
            self.offsets[path] += len(data)
            self.behind = self.behind or len(data) == self.CHUNK
            lines = (self.partial[path] + data).split(b"\n")
            self.partial[path] = lines.pop()
            for raw in lines:
                self.lines[path] += 1
                ev, problem = _parse(raw + b"\n")
                if ev is None:
                    number = self.lines[path]
                    self.bad[path] = (_not_a_trace(path, number, problem) if number == 1 else
                                      f"{path} stops at line {number} (byte "
                                      f"{self.line_end[path]}): {problem}; no longer following it")
                    break
                self.line_end[path] += len(raw) + 1
                self.who[path].take(ev)
                out.append(ev)
        out.sort(key=lambda ev: ev["t"])
        return out


# --------------------------------------------------------------------------- runs


@dataclass
class Run:
    """Processes that ran together: on one master (port), overlapping in time."""

    processes: List[Process]
    events: List[Dict[str, Any]]

    @property
    def start(self) -> float:
        return min(p.first for p in self.processes)

    @property
    def end(self) -> float:
        return max(p.last for p in self.processes)

    @property
    def master(self) -> str:
        for proc in self.processes:
            if proc.name == "/master" and proc.uri:
                return proc.uri
        return self.processes[0].master if self.processes else ""


def split_runs(files: Iterable[TraceFile]) -> List[Run]:
    """The runs in ``files``: processes join one run when they use the same master port and
    their lifetimes overlap (directly or through others), so the traces of one session merge
    whatever file each process wrote, and unrelated sessions stay apart."""
    processes: List[Process] = []
    events: List[Dict[str, Any]] = []
    for trace_file in files:
        processes.extend(trace_file.processes)
        events.extend(trace_file.events)
    parent = list(range(len(processes)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    order = sorted(range(len(processes)), key=lambda i: processes[i].first)
    by_port: Dict[int, Tuple[int, float]] = {}  # port -> (representative, latest end so far)
    for i in order:
        proc = processes[i]
        port = proc.master_port
        seen = by_port.get(port)
        if seen is not None and proc.first <= seen[1]:
            parent[find(i)] = find(seen[0])
            by_port[port] = (seen[0], max(seen[1], proc.last))
        else:
            by_port[port] = (i, proc.last)
    groups: Dict[int, List[Process]] = {}
    for i, proc in enumerate(processes):
        groups.setdefault(find(i), []).append(proc)
    members = {id(proc): root for root, procs in groups.items() for proc in procs}
    run_events: Dict[int, List[Dict[str, Any]]] = {root: [] for root in groups}
    for ev in events:
        run_events[members[id(ev["_p"])]].append(ev)
    runs = [Run(procs, sorted(run_events[root], key=lambda ev: ev["t"]))
            for root, procs in groups.items()]
    runs.sort(key=lambda run: run.start)
    return runs


# --------------------------------------------------------------------------- exchanges


def _port(text: str) -> int:
    """The port of ``host:port``, ``http://host:port/`` or ``rosrpc://host:port`` (0 if none)."""
    if "://" in text:
        try:
            return urlparse(text).port or 0
        except ValueError:
            return 0
    head, _sep, tail = text.rpartition(":")
    return int(tail) if head and tail.isdigit() else 0


@dataclass
class Call:
    """One XML-RPC exchange, from one or both of its ends."""

    t: float
    t_reply: float
    method: str
    args: List[Any]
    reply: Any = None
    fault: str = ""
    error: str = ""
    caller: str = "?"
    callee: str = "?"
    uri: str = ""
    client: str = ""
    server: str = ""
    n: int = 0
    request: str = ""
    request_len: int = 0
    response: Optional[str] = None
    response_len: int = 0
    views: List[str] = field(default_factory=list)

    @property
    def subject(self) -> Tuple[str, str]:
        name = self.args[1] if len(self.args) > 1 and isinstance(self.args[1], str) else ""
        if self.method in TOPIC_METHODS and name:
            return "topic", name
        if self.method in SERVICE_METHODS and name:
            return "service", name
        return "other", ""

    @property
    def ok(self) -> bool:
        return not self.fault and not self.error


@dataclass
class Connection:
    """One TCPROS connection: ``client`` connected to ``server`` (addresses); or one of
    another ``protocol`` (MINROSSHM: a Unix socket, messages in shared memory)."""

    client: str
    server: str
    protocol: str = "TCPROS"
    client_node: str = "?"
    server_node: str = "?"
    kind: str = ""  # topic, service, probe ("" while no header was seen)
    name: str = ""
    sides: List[str] = field(default_factory=list)
    headers: Dict[str, List[List[str]]] = field(default_factory=dict)  # c2s / s2c -> fields
    closed: bool = False

    @property
    def subject(self) -> Tuple[str, str]:
        if self.kind == "topic":
            return "topic", self.name
        if self.kind in ("service", "probe"):
            return "service", self.name
        return "other", ""

    def header(self, direction: str) -> Dict[str, str]:
        return {key: value for key, value in self.headers.get(direction, [])}


@dataclass
class Wire:
    """Something on a TCPROS connection: ``open``, ``header``, ``frame``, ``data`` (not
    TCPROS), ``eof`` or ``close``; on a MINROSSHM one also ``segment`` and ``fallback``, and
    frames in a ``slot``. ``dir`` is ``c2s`` (client to server) or ``s2c``."""

    t: float
    what: str
    conn: Connection
    dir: str = ""
    off: int = 0
    len: int = 0
    n: int = 0
    fields: Optional[List[List[str]]] = None
    head: str = ""
    ok: int = -1
    msg: Any = None
    node: str = ""  # the node that did it (opened, closed)
    stats: Optional[Dict[str, Any]] = None
    views: List[str] = field(default_factory=list)
    #: when the receiver had it, if the receiver was traced (with the sender: the latency)
    t_in: float = 0.0
    sent: bool = False  # the sender's view is here (``t`` is when it went out)
    #: MINROSSHM: ``[generation, slot]`` of a frame in shared memory; a segment's
    #: ``[generation, slots, slot_size]``; a fallback's reason
    slot: Optional[List[int]] = None
    reason: str = ""

    @property
    def subject(self) -> Tuple[str, str]:
        return self.conn.subject

    def sender(self) -> str:
        return self.conn.client_node if self.dir == "c2s" else self.conn.server_node

    def receiver(self) -> str:
        return self.conn.server_node if self.dir == "c2s" else self.conn.client_node


Item = Any  # Call | Wire


class Names:
    """Which node is behind a port, learnt from the trace itself."""

    def __init__(self, master_uri: str = "") -> None:
        self.by_port: Dict[int, str] = {}
        if master_uri:
            self.by_port[_port(master_uri)] = "/master"

    def learn(self, ev: Dict[str, Any]) -> None:
        kind = ev["ev"]
        node = str(ev.get("node", ""))
        if kind == "process" and ev.get("master"):
            port = _port(str(ev["master"]))
            if port:
                self.by_port.setdefault(port, "/master")
        elif kind == "node":
            self._set(str(ev.get("uri", "")), str(ev.get("name", node)))
        elif kind == "xmlrpc.serve":
            self._set(str(ev.get("local", "")), node)
        elif kind == "tcp.open" and ev.get("side") == "accept":
            self._set(str(ev.get("local", "")), node)
        if kind in ("xmlrpc.call", "xmlrpc.serve"):
            args = ev.get("args") or []
            method = ev.get("method")
            if method in ("registerPublisher", "registerSubscriber") and len(args) == 4:
                self._set(str(args[3]), str(args[0]))
            elif method == "registerService" and len(args) == 4:
                self._set(str(args[2]), str(args[0]))
                self._set(str(args[3]), str(args[0]))
            elif method == "requestTopic" and kind == "xmlrpc.call":
                reply = ev.get("reply")
                if (isinstance(reply, list) and len(reply) == 3 and isinstance(reply[2], list)
                        and len(reply[2]) == 3 and isinstance(reply[2][2], int)):
                    callee = self.by_port.get(_port(str(ev.get("uri", ""))))
                    if callee:
                        self.by_port.setdefault(reply[2][2], callee)

    def _set(self, where: str, name: str) -> None:
        port = _port(where)
        if port and name and name != "?":
            self.by_port[port] = name

    def name(self, where: str, default: str = "?") -> str:
        return self.by_port.get(_port(where), default) if where else default


class Merger:
    """Events (in time order) in, items out: one :class:`Call` per XML-RPC exchange and one
    :class:`Wire` per header, frame, open and close, whichever ends were traced. ``add``
    returns the new item, or None when the event was another view of a known one (that item,
    now completed by the second view, is then ``joined``).

    With a ``limit`` (following a trace that grows for as long as a system runs), the items
    are not kept, each table that joins the views remembers its ``limit`` newest entries (the
    second view of an exchange comes moments after the first), and of what an item holds, the
    HTTP texts and the frame bytes past :data:`LIVE_HEAD` are left out."""

    def __init__(self, names: Names, limit: Optional[int] = None) -> None:
        self.names = names
        self.limit = limit
        self.calls: Dict[Tuple[str, str, int], Call] = {}
        self.conns: Dict[Tuple[str, str], Connection] = {}
        self.by_proc_conn: Dict[Tuple[int, int], Tuple[Connection, str]] = {}
        self.seen: Dict[Tuple[Any, ...], Wire] = {}
        self.items: List[Item] = []
        self.joined: Optional[Item] = None

    def add(self, ev: Dict[str, Any]) -> Optional[Item]:
        self.joined = None
        kind = ev["ev"]
        if kind in ("xmlrpc.call", "xmlrpc.serve"):
            item = self._call(ev)
        elif kind.startswith("tcp"):
            item = self._wire(ev)
        else:
            item = None
        if self.limit is None:
            if item is not None:
                self.items.append(item)
        else:
            for table in (self.calls, self.conns, self.by_proc_conn, self.seen):
                while len(table) > self.limit:
                    del table[next(iter(table))]  # the oldest entry
        return item

    def _http(self, text: Any) -> Optional[str]:
        """The HTTP text of a call: not kept by a live view, which does not print it."""
        return None if text is None or self.limit is not None else str(text)

    def _head(self, text: str) -> str:
        """A frame's first bytes (hex): a live view keeps what it prints."""
        return text if self.limit is None else text[:LIVE_HEAD * 2]

    # -- XML-RPC

    def _call(self, ev: Dict[str, Any]) -> Optional[Call]:
        served = ev["ev"] == "xmlrpc.serve"
        local, remote = str(ev.get("local", "")), str(ev.get("remote", ""))
        client, server = (remote, local) if served else (local, remote)
        key = (client, server, int(ev.get("n", 0)))
        view = "serve" if served else "call"
        known = self.calls.get(key) if client and server else None
        if known is not None and view not in known.views and known.method == ev.get("method"):
            known.views.append(view)
            self.joined = known
            if served:
                known.callee = str(ev.get("node", known.callee))
            else:
                known.caller = str(ev.get("node", known.caller))
                known.t = min(known.t, ev["t"])
            return None
        args = list(ev.get("args") or [])
        node = str(ev.get("node", "?"))
        if served:
            caller = args[0] if args and isinstance(args[0], str) else self.names.name(client)
            callee = node
        else:
            caller = node
            callee = self.names.name(server or str(ev.get("uri", "")), str(ev.get("uri", "?")))
        call = Call(t=ev["t"], t_reply=ev.get("t_reply", ev["t"]), method=str(ev.get("method")),
                    args=args, reply=ev.get("reply"), fault=str(ev.get("fault", "")),
                    error=str(ev.get("error", "")), caller=caller, callee=callee,
                    uri=str(ev.get("uri", "")), client=client, server=server,
                    n=int(ev.get("n", 0)), request=self._http(ev.get("request")) or "",
                    request_len=int(ev.get("request_len", 0)),
                    response=self._http(ev.get("response")),
                    response_len=int(ev.get("response_len", 0)), views=[view])
        if client and server:
            self.calls[key] = call
        return call

    # -- TCPROS

    def _wire(self, ev: Dict[str, Any]) -> Optional[Wire]:
        proc = ev["_p"]
        kind = ev["ev"]
        conn_id = int(ev.get("conn", 0))
        node = str(ev.get("node", "?"))
        if kind == "tcp.open":
            side = str(ev.get("side"))
            local, remote = str(ev.get("local", "")), str(ev.get("remote", ""))
            key = (local, remote) if side == "connect" else (remote, local)
            conn = self.conns.get(key)
            fresh = conn is None or side in conn.sides
            if fresh:
                conn = Connection(client=key[0], server=key[1],
                                  protocol=str(ev.get("protocol", "TCPROS")))
                conn.server_node = self.names.name(key[1])
                self.conns[key] = conn
            assert conn is not None
            conn.sides.append(side)
            if side == "connect":
                conn.client_node = node
            else:
                conn.server_node = node
            self.by_proc_conn[(id(proc), conn_id)] = (conn, side)
            if not fresh:
                return None
            return Wire(t=ev["t"], what="open", conn=conn, node=conn.client_node, views=[side])
        found = self.by_proc_conn.get((id(proc), conn_id))
        if found is None:  # a connection opened before the trace began
            return None
        conn, side = found
        direction = str(ev.get("dir", ""))
        flow = "c2s" if (direction == "out") == (side == "connect") else "s2c"
        if kind in ("tcp.close", "tcp.eof"):
            what = "close" if kind == "tcp.close" else "eof"
            if what == "close":
                first = not conn.closed
                conn.closed = True
            else:
                first = False
            stats = {k: ev[k] for k in ("sent", "received", "frames_out", "frames_in",
                                        "untraced_out", "untraced_in") if k in ev}
            stats["side"] = side
            item = Wire(t=ev["t"], what=what, conn=conn, node=node, stats=stats, views=[side])
            item.n = 1 if first else 2  # the first close of a connection, or a later one
            return item
        what = {"tcpros.header": "header", "tcpros.frame": "frame", "tcp.data": "data",
                "tcpros.segment": "segment", "tcpros.fallback": "fallback"}.get(kind)
        if what is None:
            return None
        key = (conn.client, conn.server, id(conn), what, flow, int(ev.get("off", 0)))
        known = self.seen.get(key)
        if known is not None:
            known.views.append(side)
            self.joined = known
            if known.msg is None and ev.get("msg") is not None:
                known.msg = ev["msg"]
            if direction == "in":
                known.t_in = ev["t"]
            else:
                known.sent = True
                known.t = min(known.t, ev["t"])
            return None
        item = Wire(t=ev["t"], what=what, conn=conn, dir=flow, off=int(ev.get("off", 0)),
                    len=int(ev.get("len", 0)), n=int(ev.get("n", 0)),
                    head=self._head(str(ev.get("head", ""))), ok=int(ev.get("ok", -1)),
                    msg=ev.get("msg"), node=node, views=[side])
        if direction == "in":
            item.t_in = ev["t"]
        else:
            item.sent = True
        slot = ev.get("slot")
        if isinstance(slot, list):
            item.slot = [int(x) for x in slot if isinstance(x, int)]
        elif what == "segment":
            item.slot = [int(ev.get(k, 0)) for k in ("generation", "slots", "slot_size")]
        elif what == "fallback":
            item.reason = str(ev.get("reason", ""))
        if what == "header":
            item.fields = [list(pair) for pair in ev.get("fields") or []]
            conn.headers.setdefault(flow, item.fields)
            fields = dict((k, v) for k, v in item.fields)
            if flow == "c2s":
                if "topic" in fields:
                    conn.kind, conn.name = "topic", fields["topic"]
                elif "service" in fields:
                    conn.kind = "probe" if fields.get("probe") == "1" else "service"
                    conn.name = fields["service"]
                if fields.get("callerid") and conn.client_node == "?":
                    conn.client_node = fields["callerid"]
            elif fields.get("callerid") and conn.server_node == "?":
                conn.server_node = fields["callerid"]
        self.seen[key] = item
        return item


def merge(run: Run) -> Tuple[List[Item], Names]:
    """Every item of a run, in time order, with names learnt from the whole run first."""
    names = Names(run.master)
    for ev in run.events:
        names.learn(ev)
    merger = Merger(names)
    for ev in run.events:
        merger.add(ev)
    return merger.items, names
