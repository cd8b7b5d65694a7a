"""The page's Wire view, server side: wire traces followed live, their items as the steps the
page lists per topic and service.

``minros web --trace PATH...`` follows the traces that ``minros trace`` and ``MINROS_TRACE``
write (:mod:`minros.wire.trace`), with the follow logic of ``minros trace show --follow``: the
files are read by :class:`~minros.tools.trace.merge.Follower` and turned into items by
:class:`~minros.tools.trace.show.LiveView` (both ends of an exchange joined, names learnt from
the trace, the course's step numbers, the frame limit), and each item's text is what ``show``
prints for it (:func:`~minros.tools.trace.show.item_rows`). This module only adds the page's
form of an item (:func:`step_json`: the numbered line plus the event's details as data), a
bounded store of them (:class:`WireModel`), and the thread that polls the files
(:class:`WireFeed`). A PATH is a file (which may not exist yet), a directory (every ``*.jsonl``
in it, including the ones created later) or a quoted glob pattern.
"""

from __future__ import annotations

import functools
import glob
import inspect
import json
import os
import threading
import time
from collections import OrderedDict, deque
from typing import Any, Callable, Deque, Dict, Hashable, List, Optional, Sequence, Tuple

from minros.master import MasterHandler
from minros.node import SlaveApi
from minros.tools.trace import show
from minros.tools.trace.merge import Call, Connection, Follower, Item, Wire

#: steps the server keeps, and so the most a page is sent
MAX_STEPS = 5000
#: topics and services (sections) kept; steps of further ones are counted, not kept
MAX_SECTIONS = 500
#: header values (a message_definition) longer than this are cut in a step's details
VALUE_LIMIT = 16 << 10
#: TCP connections whose header has not arrived yet, kept to place their opening
MAX_PENDING_OPENS = 1000
POLL_INTERVAL = 0.25
#: seconds an incomplete last line may stay so before the file counts as cut there
CUT_AFTER = 2.0
TRACE_SUFFIX = ".jsonl"


@functools.cache
def _api_arg_names() -> Dict[str, Tuple[str, ...]]:
    """The parameter names of every Master and Slave API method, from the handlers that serve
    them (caller_id, topic, topic_type, caller_api, ...)."""
    names: Dict[str, Tuple[str, ...]] = {}
    for cls in (SlaveApi, MasterHandler):
        for method, function in inspect.getmembers(cls, inspect.isfunction):
            params = list(inspect.signature(function).parameters)[1:]
            if not method.startswith("_") and params[:1] == ["caller_id"]:
                names[method] = tuple(params)
    return names


def arg_names(method: str) -> Tuple[str, ...]:
    """The names of an API method's arguments (none for a method the APIs do not have)."""
    return _api_arg_names().get(method, ())


def _cut(value: str, limit: int = VALUE_LIMIT) -> str:
    return value if len(value) <= limit else f"{value[:limit]}…(+{len(value) - limit} chars)"


def step_json(item: Item, conn: int = 0, conn_t: float = 0.0) -> Dict[str, Any]:
    """One item as the page shows it: the line ``minros trace show`` prints for it (step number,
    time, who to whom, text, continuation lines) and the event's details as data. ``conn`` and
    ``conn_t`` number the item's TCP connection and give its first time (the page keeps each
    connection's steps together, as ``show`` does)."""
    rows = show.item_rows(item)
    step_no, t, who, text = rows[0]
    kind, name = item.subject
    step: Dict[str, Any] = {
        "kind": kind, "name": name, "step": step_no, "t": t, "who": who, "text": text,
        "nodes": sorted(show.ends(item)), "plumbing": show.plumbing(item.subject, item),
        "type": show.type_of([item])}
    if isinstance(item, Call):
        step["what"] = "call"
        step["reply"] = {"step": show.step_of(item, reply=True), "t": item.t_reply,
                         "text": show.reply_text(item)}
        step["details"] = _call_details(item)
        return step
    step["what"] = item.what
    step["lines"] = [row[3].strip() for row in rows[1:]]
    step["conn"] = conn
    step["conn_t"] = conn_t or item.t
    step["details"] = _wire_details(item)
    return step


def _call_details(call: Call) -> Dict[str, Any]:
    names = arg_names(call.method)
    details: Dict[str, Any] = {
        "method": call.method, "caller": call.caller, "callee": call.callee,
        "uri": call.uri or (f"http://{call.server}/" if call.server else ""),
        "client": call.client, "server": call.server,
        "args": [[names[i] if i < len(names) else f"argument {i + 1}", value]
                 for i, value in enumerate(call.args)],
        "ms": round((call.t_reply - call.t) * 1000, 3),
        "request_len": call.request_len, "response_len": call.response_len,
        "traced_by": list(call.views)}
    if call.error:
        details["error"] = call.error
    elif call.fault:
        details["fault"] = call.fault
    elif isinstance(call.reply, list) and len(call.reply) == 3:
        details["code"], details["status"], details["value"] = call.reply
    else:
        details["value"] = call.reply
    return details


def _wire_details(item: Wire) -> Dict[str, Any]:
    conn = item.conn
    details: Dict[str, Any] = {"client": conn.client, "server": conn.server,
                               "client_node": conn.client_node, "server_node": conn.server_node,
                               "connection": conn.kind or "?"}
    if item.dir:
        details["dir"] = ("client -> server" if item.dir == "c2s" else "server -> client")
    if item.what == "header":
        details["fields"] = [[key, _cut(value)] for key, value in item.fields or []]
        details["len"] = item.len
        details["prefix"] = show.prefix_hex(item.len - 4)
    elif item.what == "frame":
        details.update(n=item.n, len=item.len, prefix=show.prefix_hex(item.len), offset=item.off,
                       head=show.hex_groups(item.head, 64))
        if item.ok >= 0:
            details["ok"] = item.ok
        if item.msg is not None:
            details["msg"] = item.msg
        if item.sent and item.t_in:
            details["latency_ms"] = round((item.t_in - item.t) * 1000, 3)
    elif item.what == "data":
        details.update(len=item.len, head=show.hex_groups(item.head, 64))
    elif item.what in ("close", "eof"):
        details["stats"] = dict(item.stats or {})
    if item.what == "open" and conn.kind == "probe":
        details["probe"] = True
    details["traced_by"] = list(item.views)
    return details


class WireModel:
    """The steps the pages are sent: at most ``max_steps``, in sections (one per topic and
    service, plus the other calls). Pure: items in, steps out; :class:`WireFeed` owns it.

    Each step has an ``id`` and a ``seq`` (raised whenever the step changes), so a page is sent
    what changed since the last ``seq`` it saw. When the store is full, the oldest step of the
    largest section goes, so a busy service does not push a quiet topic's sequence out. A call
    that is about no topic or service and repeats (the same caller, callee, method and failure:
    ``getPid`` probes, ``subscribeParam`` on every log line) is one step with a count, as
    ``show`` prints it."""

    def __init__(self, max_steps: int = MAX_STEPS, max_sections: int = MAX_SECTIONS) -> None:
        self.max_steps = max(1, max_steps)
        self.max_sections = max_sections
        self.steps: OrderedDict[int, Dict[str, Any]] = OrderedDict()  # id -> step, by seq
        self.sections: Dict[Tuple[str, str], Deque[int]] = {}
        self.seq = 0
        self.next_id = 1
        self.dropped = 0  # steps let go to stay within max_steps
        self.left_out = 0  # items of sections beyond max_sections
        self._repeats: Dict[Tuple[str, str, str, str], int] = {}  # other calls -> step id
        self._repeat_of: Dict[int, Tuple[str, str, str, str]] = {}
        self._items: OrderedDict[int, Tuple[Item, int]] = OrderedDict()  # id(item) -> step id
        self._conns: OrderedDict[int, Tuple[Connection, int, float]] = OrderedDict()
        self._conn_count = 0
        self._opens: OrderedDict[int, Wire] = OrderedDict()

    # -- in --------------------------------------------------------------------------------

    def add(self, item: Item) -> None:
        """A new item (from :meth:`LiveView.items`)."""
        if isinstance(item, Wire):
            key = id(item.conn)
            if item.subject[0] == "other":
                if item.what == "open":  # placed once its header names the topic or service
                    self._opens[key] = item
                    while len(self._opens) > MAX_PENDING_OPENS:
                        self._opens.popitem(last=False)
                return  # nothing else of a connection that never named what it carries
            opening = self._opens.pop(key, None)
            if opening is not None:
                self._insert(opening)
        self._insert(item)

    def refresh(self, item: Item) -> None:
        """``item``, already added, was completed by the other end's view of it."""
        known = self._items.get(id(item))
        if known is None or known[0] is not item or known[1] not in self.steps:
            return
        old = self.steps[known[1]]
        step = self._json(item)
        for key in ("id", "count", "last"):
            if key in old:
                step[key] = old[key]
        self._put(step)

    def _insert(self, item: Item) -> None:
        subject = item.subject
        repeat = None
        if isinstance(item, Call) and subject[0] == "other":
            repeat = (item.caller, item.callee, item.method, item.error or item.fault)
            known = self._repeats.get(repeat)
            if known is not None:
                step = dict(self.steps[known])
                step["count"] = step.get("count", 1) + 1
                step["last"] = item.t
                self._put(step)
                return
        section = self.sections.get(subject)
        if section is None:
            if len(self.sections) >= self.max_sections:
                self.left_out += 1
                return
            section = self.sections[subject] = deque()
        step = self._json(item)
        step["id"] = self.next_id
        self.next_id += 1
        section.append(step["id"])
        self._put(step)
        if repeat is not None:
            self._repeats[repeat] = step["id"]
            self._repeat_of[step["id"]] = repeat
        self._items[id(item)] = (item, step["id"])
        while len(self._items) > show.LIVE_LIMIT:
            self._items.popitem(last=False)
        while len(self.steps) > self.max_steps:
            self._evict()

    def _json(self, item: Item) -> Dict[str, Any]:
        if isinstance(item, Call):
            return step_json(item)
        key = id(item.conn)
        known = self._conns.get(key)
        if known is None or known[0] is not item.conn:
            self._conn_count += 1
            known = self._conns[key] = (item.conn, self._conn_count, item.t)
            while len(self._conns) > show.LIVE_LIMIT:
                self._conns.popitem(last=False)
        return step_json(item, known[1], known[2])

    def _put(self, step: Dict[str, Any]) -> None:
        self.seq += 1
        step["seq"] = self.seq
        self.steps[step["id"]] = step
        self.steps.move_to_end(step["id"])

    def _evict(self) -> None:
        subject = max(self.sections, key=lambda s: len(self.sections[s]))
        section = self.sections[subject]
        gone = section.popleft()
        if not section:
            del self.sections[subject]
        self.steps.pop(gone)
        self.dropped += 1
        repeat = self._repeat_of.pop(gone, None)
        if repeat is not None:
            del self._repeats[repeat]

    # -- out -------------------------------------------------------------------------------

    def since(self, seq: int) -> List[Dict[str, Any]]:
        """The steps added or changed after ``seq``, oldest change first."""
        out = []
        for step in reversed(self.steps.values()):
            if step["seq"] <= seq:
                break
            out.append(step)
        out.reverse()
        return out


def _pattern(spec: str) -> bool:
    return any(c in spec for c in "*?[")


def expand(spec: str) -> List[str]:
    """The trace files a ``--trace`` argument names now: a directory's ``*.jsonl``, a
    pattern's matches, or the file itself (which may not exist yet)."""
    if os.path.isdir(spec):
        return sorted(glob.glob(os.path.join(glob.escape(spec), "*" + TRACE_SUFFIX)))
    if _pattern(spec):
        return sorted(path for path in glob.glob(spec) if not os.path.isdir(path))
    return [spec]


class WireFeed:
    """Follows the trace files of ``minros web --trace`` in a thread of its own
    (``minros-web-wire``) and keeps the steps for the pages; the follower, the live view and
    the model are touched only under its lock. Listeners are told after each poll that changed
    something; they only queue (the pages' writers read :meth:`changes`)."""

    def __init__(self, specs: Sequence[str], max_steps: int = MAX_STEPS,
                 interval: float = POLL_INTERVAL,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.specs = list(specs)
        self.follower = Follower()
        self.view = show.LiveView(show.Filter(show_all=True))
        self.model = WireModel(max_steps)
        self.interval = interval
        self.clock = clock
        self.lock = threading.Lock()
        self.events = 0
        self._error = ""
        self._status: Dict[str, Any] = {}
        self._tails: Dict[str, Tuple[int, float]] = {}  # path -> (incomplete line's size, since)
        self._listeners: Dict[Hashable, Callable[[], None]] = {}
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None

    # -- the thread ------------------------------------------------------------------------

    def start(self) -> None:
        self.poll()
        self._thread = threading.Thread(target=self._loop, name="minros-web-wire", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)

    def _loop(self) -> None:
        while True:
            behind = self.poll()
            if self._stop.wait(0 if behind else self.interval):
                return

    def poll(self) -> bool:
        """Read what the files gained, tell the listeners if anything changed; True when a
        file has more to read already."""
        with self.lock:
            before = (self.model.seq, self._status)
            found = {spec: expand(spec) for spec in self.specs}
            for paths in found.values():
                for path in paths:
                    self.follower.add(path)
            events = self.follower.poll()
            self.events += len(events)
            for ev in events:
                try:
                    for item in self.view.items([ev]):
                        self.model.add(item)
                    for item in self.view.joined:
                        self.model.refresh(item)
                except Exception as exc:  # noqa: BLE001 - an event no minros writes: said, then on
                    self._error = (f"an event of the trace could not be read "
                                   f"({type(exc).__name__}: {exc}); the others are shown")
            self._status = self._make_status(found)
            changed = before != (self.model.seq, self._status)
            listeners = list(self._listeners.values()) if changed else []
            behind = self.follower.behind
        for listener in listeners:
            listener()
        return behind

    def _make_status(self, found: Dict[str, List[str]]) -> Dict[str, Any]:
        follower = self.follower
        now = self.clock()
        problems: List[str] = []
        notes: List[str] = []
        for spec, paths in found.items():
            if not paths:
                problems.append(f"{spec} holds no *{TRACE_SUFFIX} trace yet: waiting for one"
                                if os.path.isdir(spec) else
                                f"no file matches {spec} yet: waiting for one")
        for path in follower.paths:
            if path in follower.bad:
                problems.append(follower.bad[path])
                continue
            if path in follower.waiting:
                problems.append(f"{path} {follower.waiting[path]}: waiting for it")
                continue
            size = len(follower.partial[path])
            seen = self._tails.get(path)
            if not size:
                self._tails.pop(path, None)
            elif seen is None or seen[0] != size:
                self._tails[path] = (size, now)
            elif now - seen[1] >= CUT_AFTER:
                problems.append(
                    f"{path} ends in the middle of an event (line {follower.lines[path] + 1}, "
                    f"byte {follower.line_end[path]}): the file was cut, or the process writing "
                    f"it stopped mid-line; showing the {follower.lines[path]} events before it")
            restarts = follower.restarts.get(path)
            if restarts:
                notes.append(f"{path} was overwritten {restarts}× (a new run started): read "
                             "again from its start")
        if self._error:
            problems.append(self._error)
        model = self.model
        if model.dropped:
            notes.append(f"{model.dropped} older steps let go (the newest {model.max_steps} "
                         "are kept)")
        if model.left_out:
            notes.append(f"{model.left_out} steps of topics and services beyond the first "
                         f"{model.max_sections} left out")
        return {"specs": self.specs, "files": [p for p in follower.paths
                                               if p not in follower.waiting],
                "events": self.events, "t0": self.view.t0, "problems": problems,
                "notes": notes}

    # -- the pages -------------------------------------------------------------------------

    def listen(self, key: Hashable, callback: Callable[[], None]) -> None:
        with self.lock:
            self._listeners[key] = callback

    def unlisten(self, key: Hashable) -> None:
        with self.lock:
            self._listeners.pop(key, None)

    def changes(self, since: int, sent: Sequence[int]) -> Tuple[List[Dict[str, Any]], List[int],
                                                                   Dict[str, Any], int]:
        """For a page that has the steps ``sent`` as of ``since``: (steps added or changed,
        ids it should remove, the status, the seq it is now at)."""
        with self.lock:
            steps = self.model.since(since)
            removed = [i for i in sent if i not in self.model.steps]
            return steps, removed, self._status, self.model.seq


#: wire steps sent in one frame
WIRE_BATCH = 500


class WireWatch:
    """One page's place in a feed: the steps it has been sent, as of which ``seq``; its frames
    (op ``op``) say what changed since. :meth:`follow` points it at another feed (or none),
    and the next frames start afresh (``reset``)."""

    def __init__(self, op: str = "wire", batch: int = WIRE_BATCH,
                 empty_status: Optional[Dict[str, Any]] = None) -> None:
        self.op = op
        self.batch = max(1, batch)
        self.empty_status = empty_status
        self.feed: Optional[WireFeed] = None
        self.seq: Optional[int] = None  # None: the page watches nothing
        self.sent: set = set()
        self.lock = threading.Lock()

    def follow(self, feed: Optional[WireFeed]) -> Optional[WireFeed]:
        """Watch ``feed`` from its start (None: no feed, but a watch: one frame of nothing
        when ``empty_status`` is given); returns the feed watched before."""
        with self.lock:
            old, self.feed = self.feed, feed
            self.seq, self.sent = 0, set()
            return old

    def frames(self) -> List[str]:
        """What changed since the last frames, in frames of ``batch`` steps (the page drops
        what is ``removed``: the store keeps the newest steps)."""
        with self.lock:
            feed, since, sent = self.feed, self.seq, self.sent
        if since is None:
            return []
        if feed is None:
            if since != 0 or self.empty_status is None:
                return []
            with self.lock:
                if self.sent is not sent:
                    return []
                self.seq = -1  # told once
            return [json.dumps({"op": self.op, "steps": [], "removed": [], "reset": True,
                                "status": self.empty_status})]
        steps, removed, status, seq = feed.changes(since, sent)
        sent.difference_update(removed)
        sent.update(step["id"] for step in steps)
        with self.lock:
            if self.sent is not sent:  # followed anew meanwhile: a new start
                return []
            self.seq = seq
        frames = []
        for start in range(0, max(1, len(steps)), self.batch):
            frame: Dict[str, Any] = {"op": self.op, "steps": steps[start:start + self.batch]}
            if start == 0:
                frame["removed"] = removed
                if since == 0:
                    frame["reset"] = True
            if start + self.batch >= len(steps):
                frame["status"] = status
            frames.append(json.dumps(frame))
        return frames
