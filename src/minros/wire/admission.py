"""Fair admission for minros's servers (master and node XML-RPC, TCPROS, ``minros web``): who
may connect, whom to close when the server is full, how long a request may take to arrive,
and how much memory a request in progress may hold.

A pure policy, without sockets: a server tells it what each connection is doing (waiting for a
request, reading one, being served) and closes the connections it names. The rules:

* **allow-list**: with ROS_ALLOWED_HOSTS set (:func:`minros.rosenv.allowed_hosts`) a peer
  outside it is refused at once, and the refusal is reported at most once a minute per peer;
* **deadlines a trickling client cannot extend**: a request's head must arrive within
  ``head_timeout`` of its first byte and its body within ``head_timeout + length / min_rate``
  (fixed when the length is known), however slowly bytes keep coming;
* **memory charged as bytes arrive**, never as announced: a request that announces 64 MiB and
  sends nothing holds nothing. When the budget is full the oldest unfinished requests (the
  slowest) are closed to make room, and a newer one that still does not fit is refused;
* **eviction at the cap**: a full server closes the connection that has produced nothing for
  the longest time, idle or half-read, taken from the peer holding the most connections;
  connections being served are never closed;
* **a per-peer share**: a peer address holding more than ``peer_share`` of the connections
  makes room from its own idlest one, and its requests hold at most that share of the memory
  budget, so a remote flood closes its own connections, not the others'.
"""

from __future__ import annotations

import itertools
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from minros import rosenv

__all__ = ["ADMIT_GRACE", "Admission", "BUSY", "Connection", "IDLE", "Limits", "READING", "Refused"]

#: a connection waiting for its next request
IDLE = 0
#: a connection whose request has started to arrive
READING = 1
#: a connection being served (or a long-lived stream): never evicted
BUSY = 2


@dataclass(frozen=True)
class Limits:
    """The numbers of the policy (see the module docstring)."""

    max_connections: int = 1024
    #: the fraction of the connections and of the budget one peer address may hold
    peer_share: float = 0.75
    #: seconds for a request's head (HTTP request line and headers, a connection header)
    head_timeout: float = 10.0
    #: bytes per second a body must at least arrive at (its deadline is fixed from its length)
    min_rate: float = 256 * 1024
    #: seconds a kept-alive connection may wait for its next request
    idle_timeout: float = 60.0
    #: bytes of requests in memory at once, all connections together
    budget: int = 256 << 20

    def transfer_time(self, length: int) -> float:
        """Seconds allowed to move ``length`` bytes (a body, a reply) after the head."""
        return self.head_timeout + length / self.min_rate

    def body_deadline(self, start: float, length: int) -> float:
        """When a request that started at ``start`` and announced ``length`` bytes must be in."""
        return start + self.transfer_time(length)

    @property
    def peer_connections(self) -> int:
        return max(1, int(self.max_connections * self.peer_share))

    @property
    def peer_budget(self) -> int:
        return max(1, int(self.budget * self.peer_share))


class Refused(Exception):
    """A connection or request the policy turns away; ``str()`` says why, for the peer."""

    def __init__(self, reason: str, status: int = 503, report: bool = False) -> None:
        super().__init__(reason)
        self.status = status
        #: whether the server should log this refusal now (allow-list refusals, rate-limited)
        self.report = report


class _Ticket:
    __slots__ = ("key", "peer", "state", "since", "held", "evicted")

    def __init__(self, key: Any, peer: str, now: float) -> None:
        self.key = key
        self.peer = peer
        self.state = IDLE
        self.since = now
        self.held = 0
        self.evicted = False


#: how long a server's accept waits, when every connection is being served, for one to become
#: idle or leave before refusing (the moment between a reply sent and its connection marked idle)
ADMIT_GRACE = 0.2
#: refusals of distinct peers remembered for rate-limiting their log lines
_MAX_REPORTED = 1024


class Admission:
    """The policy of one server. Thread-safe; every method is O(connections) at worst."""

    def __init__(self, limits: Limits | None = None,
                 allowed: Optional[Sequence[rosenv.Network]] = None, *,
                 clock: Callable[[], float] = time.monotonic, report_interval: float = 60.0,
                 what: str = "") -> None:
        self.limits = limits or Limits()
        self.allowed = allowed
        self.clock = clock
        self.report_interval = report_interval
        #: named in refusals: "the master", "/talker's TCPROS server", ...
        self.what = what or "this server"
        self._lock = threading.Lock()
        #: notified when a connection becomes idle or leaves (admit's grace waits on it)
        self._changed = threading.Condition(self._lock)
        self._tickets: Dict[Any, _Ticket] = {}
        self._by_peer: Dict[str, Dict[Any, _Ticket]] = {}
        self._live = 0
        self._held = 0
        self._peer_held: Dict[str, int] = {}
        self._reported: Dict[str, float] = {}
        self._keys = itertools.count(1)
        # the limits are frozen: charge() compares with these on every request (a peer's
        # share of the whole budget or more is no limit of its own)
        self._budget = self.limits.budget
        self._peer_budget = (self.limits.peer_budget if self.limits.peer_budget < self._budget
                             else 1 << 62)
        self.evictions = 0
        self.refusals = 0

    def new_key(self) -> int:
        """A fresh connection key (never reused, unlike ``id()`` of a socket)."""
        return next(self._keys)

    # -- connections -----------------------------------------------------------------------

    def admit(self, key: Any, peer: str, local: str | None = None,
              grace: float = 0.0) -> List[Any]:
        """Register connection ``key`` from address ``peer`` (arrived at address ``local``).
        Returns the keys of the connections to close to make room for it; raises Refused when
        the peer is not allowed or nothing can make room (every connection is being served)
        within ``grace`` seconds: a server's thread marks its connection idle only after the
        reply went, so a client that calls again at once, on a new connection, can arrive
        before the one it just used is idle."""
        if not rosenv.host_allowed(peer, self.allowed, local):
            with self._lock:
                self.refusals += 1
                report = self._should_report(peer)
            raise Refused(f"connection from {peer} refused: not in {rosenv.ALLOWED_HOSTS_VAR} "
                          f"of {self.what}", status=403, report=report)
        deadline = self.clock() + grace
        with self._lock:
            while True:
                victims = self._room_for(peer)
                if victims is not None:
                    break
                remaining = deadline - self.clock()
                if remaining <= 0:
                    self.refusals += 1
                    raise Refused(f"{self.what} is serving {self._live} connections: try again")
                self._changed.wait(remaining)
            ticket = _Ticket(key, peer, self.clock())
            self._tickets[key] = ticket
            self._by_peer.setdefault(peer, {})[key] = ticket
            self._live += 1
            return victims

    def _room_for(self, peer: str) -> List[Any] | None:
        """With the lock: the connections to close to make room for one more of ``peer``
        (evicted now); None when nothing can make room."""
        limits = self.limits
        victims: List[Any] = []
        mine = self._by_peer.get(peer, {})
        # a peer over its share makes room itself, from its own idlest connection
        victim = None
        if sum(1 for t in mine.values() if not t.evicted) >= limits.peer_connections:
            victim = self._oldest(mine.values(), (IDLE, READING))
        if victim is not None:
            victims.append(self._evict(victim))
        elif self._live >= limits.max_connections:
            victim = self._victim_at_cap()
            if victim is None:
                return None
            victims.append(self._evict(victim))
        return victims

    def leave(self, key: Any) -> None:
        """Connection ``key`` is closed: forget it and what it held."""
        with self._lock:
            ticket = self._tickets.pop(key, None)
            if ticket is None:
                return
            peers = self._by_peer.get(ticket.peer)
            if peers is not None:
                peers.pop(key, None)
                if not peers:
                    del self._by_peer[ticket.peer]
            if not ticket.evicted:
                self._live -= 1
                self._uncharge(ticket)
            self._changed.notify_all()

    def set_state(self, key: Any, state: int) -> None:
        """Connection ``key`` now waits (IDLE), reads a request (READING) or is served (BUSY)."""
        with self._lock:
            ticket = self._tickets.get(key)
            if ticket is not None:
                ticket.state = state
                ticket.since = self.clock()
                if state != BUSY:
                    self._changed.notify_all()

    def evicted(self, key: Any) -> bool:
        with self._lock:
            ticket = self._tickets.get(key)
            return ticket is None or ticket.evicted

    def live(self) -> int:
        """Connections admitted and not closed or evicted."""
        with self._lock:
            return self._live

    # -- memory ----------------------------------------------------------------------------

    def charge(self, key: Any, size: int, busy: bool = False) -> List[Any]:
        """``size`` more bytes of ``key``'s request are in memory (an idle connection is then
        reading a request, from now; with ``busy`` the request is whole and being served).
        Returns the connections to close to make room (older unfinished requests); raises
        Refused when the request does not fit, even so, or when its peer holds its whole
        share."""
        with self._lock:
            ticket = self._tickets.get(key)
            if ticket is None or ticket.evicted:
                raise Refused("connection closed to make room for others")
            victims: List[Any] = []
            peer = ticket.peer
            peer_held = self._peer_held.get(peer, 0) + size
            if peer_held > self._peer_budget or self._held + size > self._budget:
                if ticket.state == IDLE:
                    ticket.state = READING
                    ticket.since = self.clock()
                self._make_room_for(ticket, size, victims)
                peer_held = self._peer_held.get(peer, 0) + size
            ticket.held += size
            self._held += size
            self._peer_held[peer] = peer_held
            if busy:
                ticket.state = BUSY
            elif ticket.state == IDLE:
                ticket.state = READING
                ticket.since = self.clock()
            return victims

    def _make_room_for(self, ticket: _Ticket, size: int, victims: List[Any]) -> None:
        """``size`` more bytes of ``ticket``'s request do not fit its peer's share or the
        budget: evict older unfinished requests, or raise Refused."""
        limits = self.limits
        peer = ticket.peer
        if self._peer_held.get(peer, 0) + size > self._peer_budget:
            self._make_room(ticket, size, victims, peer)
            if self._peer_held.get(peer, 0) + size > self._peer_budget:
                raise Refused(f"requests from {peer} hold {limits.peer_budget} bytes of "
                              f"{self.what}'s memory already: try again")
        if self._held + size > self._budget:
            self._make_room(ticket, size, victims, None)
            if self._held + size > self._budget:
                raise Refused(f"{self.what} is busy with large requests: try again")

    def release(self, key: Any, idle: bool = False) -> None:
        """``key``'s request is done: the memory it held is free again (and with ``idle``
        the connection waits for its next request, from now)."""
        with self._lock:
            ticket = self._tickets.get(key)
            if ticket is not None and not ticket.evicted:
                if ticket.held:
                    self._uncharge(ticket)
                if idle:
                    ticket.state = IDLE
                    ticket.since = self.clock()

    def held(self) -> int:
        """Bytes charged right now, all connections together."""
        with self._lock:
            return self._held

    # -- internals (lock held) -------------------------------------------------------------

    def _uncharge(self, ticket: _Ticket) -> None:
        if ticket.held:
            self._held -= ticket.held
            left = self._peer_held.get(ticket.peer, 0) - ticket.held
            if left > 0:
                self._peer_held[ticket.peer] = left
            else:
                self._peer_held.pop(ticket.peer, None)
            ticket.held = 0

    def _evict(self, ticket: _Ticket) -> Any:
        ticket.evicted = True
        self._live -= 1
        self._uncharge(ticket)
        self.evictions += 1
        return ticket.key

    @staticmethod
    def _oldest(tickets: Any, states: Tuple[Any, ...]) -> _Ticket | None:
        best: _Ticket | None = None
        for t in tickets:
            if not t.evicted and t.state in states and (best is None or t.since < best.since):
                best = t
        return best

    def _victim_at_cap(self) -> _Ticket | None:
        """The connection that has produced nothing for longest, from the peer holding most."""
        peers = sorted(self._by_peer.values(), key=len, reverse=True)
        for tickets in peers:
            victim = self._oldest(tickets.values(), (IDLE, READING))
            if victim is not None:
                return victim
        return None

    def _make_room(self, ticket: _Ticket, size: int, victims: List[Any], peer: str | None) -> None:
        """Evict requests older than ``ticket``'s (of ``peer`` only, when given), oldest
        first, until ``size`` more bytes fit."""
        pool = self._by_peer.get(peer, {}).values() if peer is not None else self._tickets.values()
        older = sorted((t for t in pool if t is not ticket and not t.evicted and t.held
                        and t.state == READING and t.since < ticket.since),
                       key=lambda t: t.since)
        limit = self.limits.peer_budget if peer is not None else self.limits.budget
        for victim in older:
            used = self._peer_held.get(peer, 0) if peer is not None else self._held
            if used + size <= limit:
                break
            victims.append(self._evict(victim))

    def _should_report(self, peer: str) -> bool:
        now = self.clock()
        last = self._reported.get(peer)
        if last is not None and now - last < self.report_interval:
            return False
        if len(self._reported) >= _MAX_REPORTED:
            for old in [p for p, t in self._reported.items() if now - t >= self.report_interval]:
                del self._reported[old]
            if len(self._reported) >= _MAX_REPORTED:
                self._reported.clear()
        self._reported[peer] = now
        return True


class Connection:
    """One admitted connection's part in the policy, for the code that serves it: it says what
    the connection is doing and charges the bytes it holds; ``evict(keys)`` closes the
    connections the policy names to make room (the server's)."""

    __slots__ = ("admission", "key", "_evict")

    def __init__(self, admission: Admission, key: Any, evict: Callable[[List[Any]], Any]) -> None:
        self.admission = admission
        self.key = key
        self._evict = evict

    @property
    def limits(self) -> Limits:
        return self.admission.limits

    def idle(self) -> None:
        self.admission.set_state(self.key, IDLE)

    def reading(self) -> None:
        self.admission.set_state(self.key, READING)

    def busy(self) -> None:
        self.admission.set_state(self.key, BUSY)

    def charge(self, size: int, busy: bool = False) -> None:
        """``size`` more bytes held (``busy``: the request is whole and being served);
        Refused when they do not fit (see Admission.charge)."""
        victims = self.admission.charge(self.key, size, busy)
        if victims:
            self._evict(victims)

    def release(self, idle: bool = False) -> None:
        """The request's memory is free again (``idle``: and the connection waits for its
        next request)."""
        self.admission.release(self.key, idle)

    def evicted(self) -> bool:
        return self.admission.evicted(self.key)
