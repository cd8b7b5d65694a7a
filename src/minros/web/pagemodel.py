"""What the web page is sent, computed without sockets: the graph as JSON, topic rates and
bandwidths, the console's ring of log lines, messages as trees small enough to show, typed YAML.

:mod:`minros.web.page` holds the sessions that send these; everything here is a pure function or
a small object that tests drive directly.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from typing import Any, Deque, Dict, List, Optional, Tuple

from minros.msgs import TVal
from minros.web.rosapi import Graph

#: lines the console keeps (rqt_console's default message limit)
MAX_LOG_LINES = 20_000
#: array items and string characters an echoed message shows before "... N more"
ECHO_MAX_ITEMS = 64
ECHO_MAX_CHARS = 2_000
#: seconds of samples behind a topic's Hz and bandwidth (rostopic hz shows a window too)
METER_WINDOW = 5.0


# -- the graph -------------------------------------------------------------------------------

def graph_json(graph: Graph, version: int, mode: str) -> Dict[str, Any]:
    """The ``graph`` message: nodes, topics (type, publishers, subscribers), services."""
    return {
        "op": "graph", "version": version, "mode": mode, "nodes": graph.nodes(),
        "topics": [{"name": t, "type": graph.topic_types.get(t, ""),
                    "publishers": sorted(graph.publishers.get(t, [])),
                    "subscribers": sorted(graph.subscribers.get(t, []))}
                   for t in graph.topics()],
        "services": [{"name": s, "providers": list(n)} for s, n in sorted(graph.services.items())],
    }


def node_info(graph: Graph, node: str) -> Dict[str, Any]:
    """``rosnode info``'s first half, from the graph: what ``node`` publishes, subscribes,
    serves (topics with their types)."""
    def of(table: Dict[str, List[str]]) -> List[List[str]]:
        return [[t, graph.topic_types.get(t, "")] for t, ids in sorted(table.items()) if node in ids]

    return {"node": node, "publications": of(graph.publishers),
            "subscriptions": of(graph.subscribers),
            "services": sorted(s for s, ids in graph.services.items() if node in ids)}


def connections(bus_info: Any) -> List[Dict[str, Any]]:
    """A node's getBusInfo rows as ``rosnode info`` lists them (connected ones only)."""
    out = []
    if not isinstance(bus_info, list):
        return out
    for row in bus_info:
        if not isinstance(row, list) or len(row) < 5:
            continue
        if len(row) > 5 and not row[5]:
            continue
        out.append({"topic": str(row[4]), "to": str(row[1]),
                    "direction": {"i": "inbound", "o": "outbound"}.get(row[2], "unknown"),
                    "transport": str(row[3])})
    return out


# -- topic statistics ------------------------------------------------------------------------

class TopicMeter:
    """Hz and bandwidth of one topic from its tap's running totals, sampled about once a second
    (rostopic hz/bw over the last :data:`METER_WINDOW` seconds)."""

    def __init__(self, window: float = METER_WINDOW) -> None:
        self.window = window
        self.samples: Deque[Tuple[float, int, int]] = deque()

    def sample(self, now: float, count: int, nbytes: int) -> Dict[str, Any]:
        """Record the totals at ``now``; ``{hz, bw, size, count}`` over the window (hz and bw
        are None until two samples exist)."""
        samples = self.samples
        samples.append((now, count, nbytes))
        while len(samples) > 2 and now - samples[1][0] >= self.window:
            samples.popleft()
        t0, c0, b0 = samples[0]
        elapsed = now - t0
        stats: Dict[str, Any] = {"count": count, "hz": None, "bw": None, "size": None}
        if elapsed > 0 and len(samples) > 1:
            messages = count - c0
            stats["hz"] = messages / elapsed
            stats["bw"] = (nbytes - b0) / elapsed
            stats["size"] = (nbytes - b0) / messages if messages else None
        return stats


# -- the console -----------------------------------------------------------------------------

LOG_LEVELS = {1: "DEBUG", 2: "INFO", 4: "WARN", 8: "ERROR", 16: "FATAL"}


def log_line(seq: int, msg: Any) -> List[Any]:
    """One rosgraph_msgs/Log as the page's row: [seq, stamp s, level, node, text, file,
    function, line, topics]."""
    stamp = msg.header.stamp
    return [seq, stamp.secs + stamp.nsecs * 1e-9, int(msg.level), msg.name, msg.msg, msg.file,
            msg.function, int(msg.line), list(msg.topics)]


class LogRing:
    """The last :data:`MAX_LOG_LINES` log lines, numbered; readers ask for what follows the
    last number they saw. Written by one receive thread, read by the page sessions."""

    def __init__(self, size: int = MAX_LOG_LINES) -> None:
        self.lines: Deque[List[Any]] = deque(maxlen=size)
        self.seq = 0
        self.lock = threading.Lock()

    def add(self, msg: Any) -> List[Any]:
        with self.lock:
            self.seq += 1
            line = log_line(self.seq, msg)
            self.lines.append(line)
            return line

    def since(self, seq: int, limit: Optional[int] = None) -> List[List[Any]]:
        """Lines numbered after ``seq`` (the oldest first; at most ``limit``, the newest)."""
        with self.lock:
            if not self.lines or self.lines[-1][0] <= seq:
                return []
            first = self.lines[0][0]
            start = max(0, seq + 1 - first)
            if limit is not None:
                start = max(start, len(self.lines) - limit)
            return [self.lines[i] for i in range(start, len(self.lines))]


# -- messages as trees -----------------------------------------------------------------------

def _number(value: float) -> Any:
    return value if math.isfinite(value) else str(value)


def message_tree(msg: Any, max_items: int = ECHO_MAX_ITEMS, max_chars: int = ECHO_MAX_CHARS) -> Any:
    """``msg`` as JSON values small enough for a browser at any rate: arrays past ``max_items``
    and strings past ``max_chars`` are cut, with a note saying how much is left out; byte
    arrays are shown as hex; NaN and infinities as text."""
    if isinstance(msg, TVal):
        return {"secs": msg.secs, "nsecs": msg.nsecs}
    slots = getattr(type(msg), "__slots__", None)
    if slots is not None and hasattr(type(msg), "_slot_types"):
        return {name: message_tree(getattr(msg, name), max_items, max_chars) for name in slots}
    if isinstance(msg, (bytes, bytearray, memoryview)):
        data = bytes(msg[:max_items])
        text = data.hex(" ")
        more = len(msg) - len(data)
        return f"[{len(msg)} bytes] {text}" + (f" ... {more} more" if more > 0 else "")
    if isinstance(msg, (list, tuple)):
        items = [message_tree(v, max_items, max_chars) for v in msg[:max_items]]
        if len(msg) > max_items:
            items.append(f"... {len(msg) - max_items} more of {len(msg)}")
        return items
    if isinstance(msg, float):
        return _number(msg)
    if isinstance(msg, str):
        return msg if len(msg) <= max_chars else msg[:max_chars] + f"... {len(msg) - max_chars} more characters"
    if hasattr(msg, "tolist"):  # numpy arrays and scalars (numpy_msg)
        return message_tree(msg.tolist(), max_items, max_chars)
    return msg


# -- YAML typed by the user ------------------------------------------------------------------

class YamlError(ValueError):
    """Text that is not YAML; the message names the line and column."""


def parse_yaml(text: str) -> Any:
    """A value typed as YAML (``1`` is an int, ``1.0`` a float, ``[a, b]`` a list, ...), as
    ``rosparam set`` and ``rostopic pub`` read their arguments."""
    import yaml

    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise YamlError(f"YAML does not parse: {where}{' '.join(str(problem).split())}") from None


def dumps_yaml(value: Any) -> str:
    """A parameter value as the YAML text a user edits (flow style: one line when short), so
    that reading it back gives the same value and type (``1.0`` stays a float)."""
    import yaml

    if hasattr(value, "data") and isinstance(value.data, bytes):  # xmlrpc.client.Binary
        value = value.data
    if isinstance(value, str) and "\n" in value:
        import json

        return json.dumps(value)  # a YAML double-quoted scalar on one line ("noetic\n")
    try:
        text = yaml.safe_dump(value, default_flow_style=True, sort_keys=False, width=100)
    except yaml.YAMLError:
        return repr(value)
    return text[:-5] if text.endswith("\n...\n") else text.rstrip("\n")


def yaml_type(value: Any) -> str:
    """The type a parameter shows beside its value."""
    if isinstance(value, bool):
        return "bool"
    return {int: "int", float: "double", str: "string", list: "list", dict: "dict",
            bytes: "binary"}.get(type(value), type(value).__name__)


def param_leaves(flat: Dict[str, Any]) -> List[List[str]]:
    """``[[name, value as YAML, type], ...]`` sorted by name: what the parameter view shows
    and edits."""
    return [[name, dumps_yaml(value), yaml_type(value)] for name, value in sorted(flat.items())]
