"""``minros trace show``: the wire sequence per topic and per service, numbered as courses
number it, with the run's real values.

Topics (the 0-6 sequence of *ROS Robot Programming* and the Autolabor course):

    [0] the publisher registers (registerPublisher)
    [1] the subscriber registers (registerSubscriber)
    [2] the master tells the subscriber who publishes: the answer to registerSubscriber when
        the publisher was first, else a publisherUpdate call to the subscriber
    [3] the subscriber asks the publisher for a connection (requestTopic)
    [4] the publisher answers with its TCPROS host and port (between minros nodes of one host:
        MINROSSHM and its Unix socket)
    [5] TCP connection and the two connection headers (MINROSSHM: a Unix socket connection,
        then the shared-memory segment, its memfd passed over the socket)
    [6] messages, length-prefixed (MINROSSHM: large ones in a slot of the segment, announced
        by a record on the socket; small ones inline)

Services: [0] registerService, [1] lookupService, [2] its answer (the rosrpc:// URI), [3] TCP
connection and headers, [4] request, [5] response. Lines are in time order, so a subscriber
that registered first shows [1] before [0].
"""

from __future__ import annotations

import json
import statistics
import time
from typing import Any, Dict, Iterable, List, Optional, Sequence, Set, Tuple

from minros.tools.trace.merge import Call, Item, Merger, Names, Run, Wire, merge

__all__ = ["LEGEND", "LIVE_LIMIT", "Filter", "LiveView", "Row", "ends", "format_item",
           "hex_groups", "item_rows", "plumbing", "prefix_hex", "render", "render_run",
           "reply_text", "run_heading", "step_of", "type_of", "who_of"]

LEGEND = (
    "steps, as courses number them:\n"
    "  topic:   [0] publisher registers  [1] subscriber registers  [2] master tells the subscriber"
    " who publishes\n"
    "           [3] requestTopic  [4] publisher's TCPROS address  [5] TCP connection and headers"
    "  [6] messages\n"
    "  service: [0] registerService  [1] lookupService  [2] the server's address  [3] TCP"
    " connection and headers\n"
    "           [4] request  [5] response")

#: said under a run that has shared-memory connections
SHM_NOTE = ("MINROSSHM is minros's shared memory between minros nodes of one host: [4] the "
            "publisher's Unix socket, [5] that connection, its headers and the segment, [6] "
            "messages in the segment's slots (their bytes are not on the socket, nor in the trace)")

#: the plumbing every rospy node has: hidden unless asked for (--all, --topic, --service)
PLUMBING_TOPICS = ("/rosout", "/rosout_agg")
PLUMBING_SERVICE_SUFFIXES = ("/get_loggers", "/set_logger_level")
PLUMBING_CALLS = ("getPid",)
HEX_SHOWN = 32  # bytes of a frame body printed
WHO_WIDTH = 34  # the who -> whom column, at least


class Filter:
    """Which sections to print."""

    def __init__(self, topics: Sequence[str] = (), services: Sequence[str] = (),
                 show_all: bool = False, frames: int = 3, nodes: Sequence[str] = ()) -> None:
        self.topics = set(topics)
        self.services = set(services)
        self.nodes = set(nodes)
        self.show_all = show_all
        self.frames = frames  # frames printed per connection direction (-1: all)
        self.hidden: Dict[str, Set[str]] = {"topic": set(), "service": set(), "other": set()}

    @property
    def narrowed(self) -> bool:
        return bool(self.topics or self.services)

    def wants(self, subject: Tuple[str, str], item: Optional[Item] = None) -> bool:
        kind, name = subject
        if self.nodes and item is not None and not self.nodes & ends(item):
            return False
        if self.narrowed:
            return (kind == "topic" and name in self.topics) or (
                kind == "service" and name in self.services)
        if self.show_all or not plumbing(subject, item):
            return True
        self.hidden[kind].add(getattr(item, "method", "") if kind == "other" else name)
        return False

    def hidden_note(self) -> Optional[str]:
        parts = []
        if self.hidden["topic"]:
            parts.append("topics " + ", ".join(sorted(self.hidden["topic"])))
        if self.hidden["service"]:
            parts.append(f"{len(self.hidden['service'])} logger services")
        if self.hidden["other"]:
            parts.append("successful " + ", ".join(sorted(self.hidden["other"])) + " calls")
        if not parts:
            return None
        return "not shown (every node has them): " + "; ".join(parts) + " (--all shows them)"


def plumbing(subject: Tuple[str, str], item: Optional[Item] = None) -> bool:
    """Whether this is the plumbing every rospy node has: /rosout, the logger services, the
    master's successful getPid probes."""
    kind, name = subject
    if kind == "topic":
        return name in PLUMBING_TOPICS
    if kind == "service":
        return name.endswith(PLUMBING_SERVICE_SUFFIXES)
    return isinstance(item, Call) and item.method in PLUMBING_CALLS and item.ok


def ends(item: Item) -> Set[str]:
    if isinstance(item, Call):
        return {item.caller, item.callee}
    return {item.conn.client_node, item.conn.server_node}


# --------------------------------------------------------------------------- values


def _value(value: Any) -> str:
    return json.dumps(value, ensure_ascii=False)


def _call_text(call: Call) -> str:
    return f"{call.method}({', '.join(_value(arg) for arg in call.args)})"


def reply_text(call: Call) -> str:
    if call.error:
        return f"failed: {call.error}"
    if call.fault:
        return f"fault: {call.fault}"
    reply = call.reply
    if isinstance(reply, list) and len(reply) == 3:
        return f"<- {_value(reply[0])}, {_value(reply[1])}, {_value(reply[2])}"
    return f"<- {_value(reply)}"


def _header_lines(fields: List[List[str]]) -> List[str]:
    lines = []
    for key, value in fields:
        if key != "error" and ("\n" in value.rstrip("\n") or len(value) > 100):
            first = value.split("\n", 1)[0]
            more = value.rstrip("\n").count("\n")
            note = f"   (first line of {more + 1})" if more else f"   ({len(value)} chars)"
            lines.append(f"{key}={first[:100]}{note}")
        else:
            lines.append(f"{key}={value.rstrip(chr(10))}")
    return lines


def hex_groups(text: str, limit: int = HEX_SHOWN) -> str:
    raw = text[:limit * 2]
    groups = " ".join(raw[i:i + 8] for i in range(0, len(raw), 8))
    return groups + (" …" if len(text) > limit * 2 else "")


def _latency(item: Wire) -> str:
    """How long a frame took from the sender's send to the receiver's recv, when both ends
    were traced (one clock: the processes share the machine's)."""
    if not (item.sent and item.t_in):
        return ""
    return f", received {(item.t_in - item.t) * 1000:.2f} ms later"


def prefix_hex(size: int) -> str:
    return size.to_bytes(4, "little").hex()


# --------------------------------------------------------------------------- steps


def step_of(item: Item, reply: bool = False) -> str:
    """The course's step number of an item ("" for the ones outside the sequence)."""
    kind, _name = item.subject
    if isinstance(item, Call):
        method = item.method
        if kind == "topic":
            if reply:
                if method == "registerSubscriber" and isinstance(item.reply, list) and len(
                        item.reply) == 3 and item.reply[2]:
                    return "2"
                return "4" if method == "requestTopic" and item.ok else ""
            if method == "publisherUpdate":  # an empty list: the publishers left
                return "2" if len(item.args) > 2 and item.args[2] else ""
            return {"registerPublisher": "0", "registerSubscriber": "1",
                    "requestTopic": "3"}.get(method, "")
        if kind == "service":
            if reply:
                return "2" if method == "lookupService" and item.ok else ""
            return {"registerService": "0", "lookupService": "1"}.get(method, "")
        return ""
    if kind == "topic":
        return {"open": "5", "header": "5", "segment": "5", "frame": "6"}.get(item.what, "")
    if kind == "service":
        if item.what in ("open", "header"):
            return "3"
        if item.what == "frame":
            return "4" if item.dir == "c2s" else "5"
    return ""


# --------------------------------------------------------------------------- lines


class _Layout:
    """Column widths: the time, then who -> whom as wide as the widest in the output."""

    def __init__(self, width: int = WHO_WIDTH) -> None:
        self.width = width

    def line(self, step: str, t: float, t0: float, who: str, text: str) -> str:
        label = f"[{step}]" if step else ""
        return f"{label:>4} {t - t0:+8.3f}  {who:<{self.width}}  {text}"

    def more(self, text: str) -> str:
        return " " * (4 + 1 + 8 + 2 + self.width + 2) + text


def who_of(item: Item) -> str:
    """``sender -> receiver`` of an item."""
    if isinstance(item, Call):
        return f"{item.caller} -> {item.callee}"
    conn = item.conn
    if item.what == "open":
        return f"{conn.client_node} -> {conn.server_node}"
    if item.what in ("close", "eof"):
        other = conn.server_node if item.node == conn.client_node else conn.client_node
        return f"{item.node} x {other}"
    return f"{item.sender()} -> {item.receiver()}"


#: one line of an item: (step, time, who -> whom, text); the time is None on the lines that
#: continue the one before (a reply outside the sequence, header fields, a frame's bytes)
Row = Tuple[str, Optional[float], str, str]


def item_rows(item: Item, label: str = "") -> List[Row]:
    """What one item says, line by line (``label`` tells apart the connections of one
    section: ``#1``, ``#2``, ...)."""
    tag = f"{label} " if label else ""
    who = who_of(item)
    if isinstance(item, Call):
        rows: List[Row] = [(step_of(item), item.t, who, _call_text(item))]
        reply_step = step_of(item, reply=True)
        reply = reply_text(item)
        rows.append((reply_step, item.t_reply, "", reply) if reply_step else ("", None, "", reply))
        return rows
    conn = item.conn
    step = step_of(item)
    if item.what == "open":
        if conn.protocol == "MINROSSHM":
            return [(step, item.t, who, f"{tag}MINROSSHM: Unix socket connection {conn.client} -> "
                     f"{conn.server} (shared memory)")]
        probe = " (a probe: is the service there?)" if conn.kind == "probe" else ""
        return [(step, item.t, who, f"{tag}TCP connection {conn.client} -> {conn.server}{probe}")]
    if item.what == "segment":
        generation, slots, size = (item.slot or [0, 0, 0]) + [0] * (3 - len(item.slot or []))
        return [(step, item.t, who, f"{tag}shared-memory segment {generation}: {slots} slots of "
                 f"{size} bytes (its memfd passed with this record)")]
    if item.what == "fallback":
        return [(step, item.t, who, f"{tag}shared memory given up, TCPROS next: {item.reason}")]
    if item.what == "header":
        fields = item.fields or []
        name = "connection header" if not any(k == "error" for k, _ in fields) else \
            "connection header (refusal)"
        count = f"{len(fields)} field" + ("s" if len(fields) != 1 else "")
        rows = [(step, item.t, who, f"{tag}{name}: length prefix "
                 f"{prefix_hex(item.len - 4)} = {item.len - 4} bytes, {count}")]
        rows.extend(("", None, "", "  " + text) for text in _header_lines(fields))
        return rows
    if item.what == "frame":
        kind = "message"
        if conn.kind == "service":
            kind = "request" if item.dir == "c2s" else "response"
        status = f" ok={item.ok}," if item.ok >= 0 else ""
        if item.slot:
            generation, index = (item.slot + [0, 0])[:2]
            return [(step, item.t, who, f"{tag}{kind} {item.n}: {item.len} bytes in slot {index} "
                     f"of segment {generation} (shared memory){_latency(item)}")]
        rows = [(step, item.t, who, f"{tag}{kind} {item.n}:{status} length prefix "
                 f"{prefix_hex(item.len)} = {item.len} bytes{_latency(item)}")]
        if item.head:
            rows.append(("", None, "", f"  body {hex_groups(item.head)}"))
        if item.msg is not None:
            rows.append(("", None, "", "  = " + _value(item.msg)))
        return rows
    if item.what == "data":
        return [(step, item.t, who,
                 f"{tag}{item.len} bytes that are not TCPROS: {hex_groups(item.head, 16)}")]
    if item.what in ("close", "eof"):
        text = "closed the connection" if item.what == "close" else "saw the peer close"
        return [("", item.t, who, f"{tag}{text}")]
    return []


def format_item(item: Item, t0: float, layout: Optional[_Layout] = None,
                label: str = "") -> List[str]:
    """The lines of one item: time relative to ``t0``, who to whom, what."""
    layout = layout or _Layout()
    return [layout.more(text) if t is None else layout.line(step, t, t0, who, text)
            for step, t, who, text in item_rows(item, label)]


# --------------------------------------------------------------------------- a run


def type_of(items: List[Item]) -> str:
    """The message type of a topic's items ("" if none names it; rostopic's "*" names none)."""
    for item in items:
        if isinstance(item, Call) and item.method in ("registerPublisher", "registerSubscriber"
                                                        ) and len(item.args) > 2:
            if item.args[2] != "*":
                return str(item.args[2])
        if isinstance(item, Wire) and item.what == "header":
            fields = dict((k, v) for k, v in item.fields or [])
            if fields.get("type") and fields["type"] != "*":
                return fields["type"]
    return ""


def _by_connection(items: List[Item]) -> List[Item]:
    """Each connection's items together, from where it opened: calls and connections in time
    order, and what happened on one connection in one block, not interleaved with the
    others' (which on a busy node would be a matter of thread scheduling)."""
    starts: Dict[int, float] = {}
    for item in items:
        if isinstance(item, Wire):
            starts.setdefault(id(item.conn), item.t)
    order = {id(item): index for index, item in enumerate(items)}

    def key(item: Item) -> Tuple[float, int]:
        if isinstance(item, Wire):
            return starts[id(item.conn)], order[id(item)]
        return item.t, order[id(item)]

    return sorted(items, key=key)


def _section(title: str, items: List[Item], t0: float, flt: Filter, layout: _Layout) -> List[str]:
    items = _by_connection(items)
    labels: Dict[int, str] = {}
    for item in items:
        if isinstance(item, Wire) and id(item.conn) not in labels:
            labels[id(item.conn)] = f"#{len(labels) + 1}"
    if len(labels) < 2:
        labels = {}
    lines = [title]
    i = 0
    while i < len(items):
        item = items[i]
        if not isinstance(item, Wire):
            lines.extend(format_item(item, t0, layout))
            i += 1
            continue
        j = i
        while j < len(items) and isinstance(items[j], Wire) and items[j].conn is item.conn:
            j += 1
        lines.extend(_connection_lines(items[i:j], t0, flt, layout, labels.get(id(item.conn), "")))
        i = j
    return lines


def _connection_lines(items: List[Wire], t0: float, flt: Filter, layout: _Layout,
                      label: str) -> List[str]:
    """One connection's block: opening, headers, the first frames of each direction, what
    was left out, the send-to-receive times when both ends were traced, the close."""
    lines: List[str] = []
    shown: Dict[str, int] = {}
    more = [0, 0]  # frames and bytes not printed
    latencies: Dict[str, List[float]] = {}
    close: Optional[Wire] = None
    for item in items:
        if item.what == "frame":
            if item.sent and item.t_in:
                latencies.setdefault(item.sender(), []).append(item.t_in - item.t)
            count = shown.get(item.dir, 0)
            if 0 <= flt.frames <= count:
                more[0] += 1
                more[1] += item.len + 4
                continue
            shown[item.dir] = count + 1
        elif item.what == "eof":
            continue
        elif item.what == "close":
            close = close or item  # the first to close; printed last
            continue
        lines.extend(format_item(item, t0, layout, label))
    tag = f"{label} " if label else ""
    if more[0]:
        lines.append(layout.more(f"{tag}… {more[0]} more frames, {more[1]} bytes "
                                 "(--frames all shows them)"))
    stats = (close.stats or {}) if close is not None else {}
    untraced = int(stats.get("untraced_out", 0)) + int(stats.get("untraced_in", 0))
    if untraced:
        lines.append(layout.more(f"{tag}… and {untraced} frames the trace did not keep "
                                 "(MINROS_TRACE_FRAMES)"))
    for sender, values in latencies.items():
        lines.append(layout.more(tag + _latency_summary(sender, values)))
    if close is not None:
        lines.extend(format_item(close, t0, layout, label))
    return lines


def _latency_summary(sender: str, values: List[float]) -> str:
    """Send-to-receive times of a connection's frames (both of its ends traced)."""
    ms = sorted(v * 1000 for v in values)
    p90 = ms[min(len(ms) - 1, int(len(ms) * 0.9))]
    return (f"from {sender}: {len(ms)} frames received {statistics.median(ms):.2f} ms after "
            f"they were sent (median), 90% within {p90:.2f} ms, max {ms[-1]:.2f} ms")


def _clock(t: float) -> str:
    return time.strftime("%H:%M:%S", time.localtime(t)) + f".{int(t * 1000) % 1000:03d}"


def run_heading(run: Run, index: int, count: int) -> List[str]:
    lines = []
    span = f"{_clock(run.start)} to {_clock(run.end)} ({run.end - run.start:.1f} s)"
    prefix = f"run {index} of {count}: " if count > 1 else "run: "
    count = f"{len(run.processes)} process" + ("es" if len(run.processes) != 1 else "")
    lines.append(f"{prefix}master {run.master or '?'}, {count}, {span}")
    for proc in sorted(run.processes, key=lambda p: p.first):
        lines.append(f"  pid {proc.pid:<7} {proc.name or '?':<30} {proc.program()}")
    return lines


def render_run(run: Run, flt: Filter) -> List[str]:
    """The sections of one run: each topic, each service, then the other calls."""
    items, _names = merge(run)
    t0 = run.start
    sections: Dict[Tuple[str, str], List[Item]] = {}
    for item in items:
        subject = item.subject
        if isinstance(item, Wire) and subject[0] == "other":
            continue  # a connection that never sent a header (dropped before it)
        if not flt.wants(subject, item):
            continue
        sections.setdefault(subject, []).append(item)
    widest = max((len(who_of(item)) for part in sections.values() for item in part), default=0)
    layout = _Layout(max(WHO_WIDTH, min(widest, 72)))
    out: List[str] = []
    rank = {"topic": 0, "service": 1, "other": 2}
    for subject in sorted(sections, key=lambda s: rank[s[0]]):  # stable: first seen first
        section_items = sections[subject]
        kind, name = subject
        out.append("")
        if kind == "other":
            out.extend(_other_section(section_items, t0, layout))
            continue
        type_name = type_of(section_items)
        out.extend(_section(f"{kind} {name}" + (f"  [{type_name}]" if type_name else ""),
                            section_items, t0, flt, layout))
    if any(isinstance(item, Wire) and item.conn.protocol == "MINROSSHM"
           for part in sections.values() for item in part):
        out.extend(["", SHM_NOTE])
    return out


def _other_section(items: List[Item], t0: float, layout: _Layout) -> List[str]:
    """Calls about no topic or service. A call repeated (same caller, callee, method, and the
    same failure if it failed) is printed once, with the count."""
    lines = ["other XML-RPC calls (parameters, graph queries, probes, shutdown)"]
    repeats: Dict[Tuple[str, str, str, str], List[Any]] = {}
    order: List[Any] = []
    for item in items:
        if not isinstance(item, Call):
            continue
        key = (item.caller, item.callee, item.method, item.error or item.fault)
        if key in repeats:
            repeats[key][1] += 1
            repeats[key][2] = item.t
            continue
        repeats[key] = [item, 1, item.t]
        order.append(key)
    for entry in order:
        first, count, last = repeats[entry]
        lines.extend(format_item(first, t0, layout))
        if count > 1:
            times = "time" if count == 2 else "times"
            lines.append(layout.more(f"(and {count - 1} more {times}, the last at {last - t0:+.3f})"))
    return lines


def render(runs: List[Run], flt: Filter) -> Iterable[str]:
    """Everything ``show`` prints for ``runs``."""
    if len(runs) > 1:
        yield (f"note: these traces hold {len(runs)} unrelated runs (their processes use "
               "different masters or did not run at the same time); each is shown on its own")
    yield LEGEND
    for index, run in enumerate(runs, 1):
        yield ""
        yield from run_heading(run, index, len(runs))
        yield from render_run(run, flt)
    note = flt.hidden_note()
    if note:
        yield ""
        yield note


# --------------------------------------------------------------------------- --follow


#: exchanges a live view remembers to join their two views (see :class:`Merger`'s limit)
LIVE_LIMIT = 2_000


class LiveView:
    """``show --follow`` and ``minros web --trace``: each new item as it arrives, with the
    filter and the frame limit of ``show``; its memory stays bounded however long it runs."""

    def __init__(self, flt: Filter, limit: int = LIVE_LIMIT) -> None:
        self.flt = flt
        self.names = Names()
        self.merger = Merger(self.names, limit)
        self.limit = limit
        self.t0: Optional[float] = None
        self.shown: Dict[Tuple[int, str], List[Any]] = {}  # (connection, dir) -> [it, frames]
        #: items returned before that the other end's view completed during the last call
        self.joined: List[Item] = []

    def items(self, events: Iterable[Dict[str, Any]]) -> List[Item]:
        """The new items of ``events`` the filter wants, in order."""
        out: List[Item] = []
        self.joined = []
        for ev in events:
            if self.t0 is None:
                self.t0 = ev["t"]
            self.names.learn(ev)
            item = self.merger.add(ev)
            if item is None:
                if self.merger.joined is not None:
                    self.joined.append(self.merger.joined)
                continue
            subject = item.subject
            if isinstance(item, Wire):
                if item.what == "eof" or (item.what == "close" and item.n != 1):
                    continue
                if item.what == "frame" and not self._frame_wanted(item):
                    continue
            if subject[0] != "other" or isinstance(item, Call) or item.what == "open":
                if not self.flt.wants(subject, item):
                    continue
            out.append(item)
        return out

    def _frame_wanted(self, item: Wire) -> bool:
        key = (id(item.conn), item.dir)
        entry = self.shown.get(key)
        if entry is None:
            entry = self.shown[key] = [item.conn, 0]  # the connection kept: its id stays its own
            while len(self.shown) > self.limit:
                del self.shown[next(iter(self.shown))]
        entry[1] += 1
        return not 0 <= self.flt.frames < entry[1]

    def feed(self, events: Iterable[Dict[str, Any]]) -> List[str]:
        """The lines ``show --follow`` prints for ``events``."""
        out: List[str] = []
        fresh = self.t0 is None
        items = self.items(events)
        if fresh and self.t0 is not None:
            out.append(f"following since {_clock(self.t0)} (times are seconds from then)")
        for item in items:
            subject = item.subject
            tag = f"{subject[0]} {subject[1]}" if subject[1] else "(connection)"
            if subject[0] == "other" and isinstance(item, Call):
                tag = "call"
            lines = format_item(item, self.t0 or item.t)
            out.append(f"{tag}: " + lines[0].lstrip())
            out.extend("    " + line.strip() for line in lines[1:])
        return out
