"""What a trace shows, read for the checkers: XML-RPC calls, TCPROS connections with both
headers and their frames, send-to-receive times across two traces. Pure: events in.

The events are those of :mod:`minros.wire.trace` (one JSON object per line); a trace file is
one process's view, or several processes' when they shared the file.
"""

from __future__ import annotations

import statistics
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, Optional, Tuple

__all__ = ["Conn", "Latency", "calls", "connections", "latency", "node_names", "replied"]

Event = Dict[str, Any]


def calls(events: Iterable[Event], method: str, name: Optional[str] = None,
          served: bool = False) -> List[Event]:
    """The XML-RPC calls of ``method`` a process made (``served``: answered), about topic or
    service ``name`` (their second argument) when given."""
    kind = "xmlrpc.serve" if served else "xmlrpc.call"
    out = []
    for ev in events:
        if ev.get("ev") != kind or ev.get("method") != method:
            continue
        args = ev.get("args") or []
        if name is not None and (len(args) < 2 or args[1] != name):
            continue
        out.append(ev)
    return out


def replied(ev: Event) -> Optional[List[Any]]:
    """The ``[code, status, value]`` reply of a call event, if it got one."""
    reply = ev.get("reply")
    if isinstance(reply, list) and len(reply) == 3:
        return reply
    return None


def node_names(events: Iterable[Event]) -> List[str]:
    """The ROS names the processes of a trace had (their ``node`` lines)."""
    names: List[str] = []
    for ev in events:
        if ev.get("ev") == "node" and ev.get("name") and ev["name"] not in names:
            names.append(str(ev["name"]))
    return names


@dataclass
class Conn:
    """One TCPROS connection as one of its ends traced it."""

    pid: int
    id: int
    side: str  # connect (this end is the client) or accept
    local: str
    remote: str
    node: str
    out: Dict[str, str] = field(default_factory=dict)  # the header this end sent
    inn: Dict[str, str] = field(default_factory=dict)  # the header it received
    frames_in: List[Event] = field(default_factory=list)
    frames_out: List[Event] = field(default_factory=list)
    closed: Optional[Event] = None

    @property
    def client_header(self) -> Dict[str, str]:
        return self.out if self.side == "connect" else self.inn

    @property
    def server_header(self) -> Dict[str, str]:
        return self.inn if self.side == "connect" else self.out

    @property
    def kind(self) -> str:
        """``topic``, ``service``, ``probe`` ("" before the client's header)."""
        client = self.client_header
        if "topic" in client:
            return "topic"
        if "service" in client:
            return "probe" if client.get("probe") == "1" else "service"
        return ""

    @property
    def name(self) -> str:
        client = self.client_header
        return client.get("topic") or client.get("service") or ""

    @property
    def refused(self) -> str:
        """The error a header of this connection carried ("" when none did)."""
        return self.out.get("error") or self.inn.get("error") or ""


def connections(events: Iterable[Event], topic: Optional[str] = None,
                service: Optional[str] = None, side: Optional[str] = None) -> List[Conn]:
    """The TCPROS connections of a trace, in the order they opened; only those of ``topic``
    or ``service`` (probes included) and of this ``side`` when given."""
    conns: Dict[Tuple[int, int], Conn] = {}
    for ev in events:
        kind = ev.get("ev")
        key = (int(ev.get("pid", 0)), int(ev.get("conn", 0)))
        if kind == "tcp.open":
            conns[key] = Conn(pid=key[0], id=key[1], side=str(ev.get("side")),
                              local=str(ev.get("local", "")), remote=str(ev.get("remote", "")),
                              node=str(ev.get("node", "")))
            continue
        conn = conns.get(key)
        if conn is None:
            continue
        if kind == "tcpros.header":
            fields = {str(pair[0]): str(pair[1]) for pair in ev.get("fields") or []
                      if isinstance(pair, list) and len(pair) == 2}
            if ev.get("dir") == "out":
                conn.out = fields
            else:
                conn.inn = fields
        elif kind == "tcpros.frame":
            (conn.frames_out if ev.get("dir") == "out" else conn.frames_in).append(ev)
        elif kind == "tcp.close":
            conn.closed = ev
    out = list(conns.values())
    if topic is not None:
        out = [c for c in out if c.kind == "topic" and c.name == topic]
    if service is not None:
        out = [c for c in out if c.kind in ("service", "probe") and c.name == service]
    if side is not None:
        out = [c for c in out if c.side == side]
    return out


@dataclass
class Latency:
    """Send-to-receive times of one connection's frames, in milliseconds."""

    frames: int
    median: float
    p90: float
    max: float

    def text(self) -> str:
        return (f"{self.frames} frames: median {self.median:.2f} ms, 90% within {self.p90:.2f} ms,"
                f" max {self.max:.2f} ms")


def latency(receiver: Conn, sender_events: Iterable[Event]) -> Optional[Latency]:
    """How long ``receiver``'s frames took from the sender's ``send`` to its ``recv``: the
    sender's view of the same connection (its addresses reversed) is in ``sender_events``,
    and a frame is the same frame at the same stream offset. None when nothing matches."""
    peers = [c for c in connections(sender_events)
             if c.local == receiver.remote and c.remote == receiver.local]
    if not peers:
        return None
    sent = {int(f.get("off", -1)): float(f["t"]) for f in peers[0].frames_out}
    delays = sorted((float(f["t"]) - sent[int(f.get("off", -1))]) * 1000
                    for f in receiver.frames_in if int(f.get("off", -1)) in sent)
    if not delays:
        return None
    return Latency(len(delays), statistics.median(delays),
                   delays[min(len(delays) - 1, int(len(delays) * 0.9))], delays[-1])
