"""Discovery state of zenoh-bridge-ros1's beacons, without sockets (times are arguments).

A bridge declares each ROS resource it bridges by sending an empty sample on the resource's
discovery key every second (``BEACON_PERIOD``); a resource whose beacon has been silent for
three periods (``LOST_AFTER``) is lost (zenoh-plugin-ros1 ``aloha_declaration.rs``,
``aloha_subscription.rs``; its check runs once per 3 s, so it notices a loss after 3 to 6 s,
this table after 3 s plus the caller's tick).

``RemoteTable`` is what a bridge heard (and when each resource was first heard: older ones
keep their bridges when a flood of new ones arrives); ``Declarations`` what it sends and when;
``OnceLog`` keeps a misbehaving peer to one log line per distinct fault, ``BoundLog`` to one
line when a bound is first hit and then one a minute; ``TokenBucket`` is the rate at which
beacons may create bridges.
"""

from __future__ import annotations

import threading
from typing import Callable, Dict, FrozenSet, List, Optional, Set, Tuple

from minros.zenoh.keys import KeyMappingError, Resource, discovery_key, parse_discovery_key

__all__ = ["BEACON_PERIOD", "LOST_AFTER", "BoundLog", "Chatter", "Declarations", "OnceLog",
           "RemoteTable", "TableFull", "TokenBucket"]

BEACON_PERIOD = 1.0
LOST_AFTER = 3.0 * BEACON_PERIOD
#: bound on the resources remembered from peers (a peer inventing keys cannot grow it further)
MAX_REMOTE = 20000


class TableFull(KeyMappingError):
    """A new remote resource while the table holds ``max_entries``."""


class OnceLog:
    """Log each distinct fault once; after ``limit`` of them, one line says the rest are quiet."""

    def __init__(self, log: Callable[[str], None], limit: int = 200) -> None:
        self._log = log
        self._seen: Set[str] = set()
        self._limit = limit
        self._lock = threading.Lock()
        self._silenced = False

    def __call__(self, fault: str, text: Optional[str] = None) -> bool:
        """Log ``text`` (default ``fault``) if ``fault`` was not logged before; True if logged."""
        with self._lock:
            if fault in self._seen:
                return False
            if len(self._seen) >= self._limit:
                if self._silenced:
                    return False
                self._silenced = True
                text, fault = f"more than {self._limit} distinct faults: further ones are not logged", ""
            self._seen.add(fault)
        self._log(text if text is not None else fault)
        return True


class BoundLog:
    """One line when a bound is first hit, then at most one every ``interval`` seconds with
    how many times it was hit meanwhile (a flood must not flood the log)."""

    def __init__(self, log: Callable[[str], None], interval: float = 60.0) -> None:
        self._log = log
        self.interval = interval
        self._last: Dict[str, float] = {}
        self._count: Dict[str, int] = {}
        self._lock = threading.Lock()

    def __call__(self, bound: str, text: str, now: float) -> bool:
        """``text`` about ``bound``, logged unless said within the interval; True if logged."""
        with self._lock:
            last = self._last.get(bound)
            if last is not None and now - last < self.interval:
                self._count[bound] = self._count.get(bound, 0) + 1
                return False
            count = self._count.pop(bound, 0)
            self._last[bound] = now
        more = f" ({count} more times since the last report)" if count else ""
        self._log(text + more)
        return True


class Chatter:
    """At most ``budget`` lines every ``interval`` seconds (the bridges made and lost for
    remote beacons: a peer that keeps inventing names must not grow the log at its pace);
    the first line after a quiet spell says how many were not written."""

    def __init__(self, log: Callable[[str], None], budget: int = 100,
                 interval: float = 60.0) -> None:
        self._log = log
        self.budget = budget
        self.interval = interval
        self._start = -float("inf")
        self._written = 0
        self._quiet = 0

    def __call__(self, text: str, now: float) -> bool:
        if now - self._start >= self.interval:
            if self._quiet:
                self._log(f"{self._quiet} more lines about bridges for remote beacons were "
                          f"not written (at most {self.budget} every {self.interval:g} s)")
            self._start, self._written, self._quiet = now, 0, 0
        if self._written >= self.budget:
            self._quiet += 1
            return False
        self._written += 1
        self._log(text)
        return True


class TokenBucket:
    """``rate`` tokens a second, at most ``burst`` saved up (times are arguments)."""

    def __init__(self, rate: float, burst: float, now: float = 0.0) -> None:
        self.rate = rate
        self.burst = burst
        self.tokens = burst
        self._at = now

    def take(self, now: float) -> bool:
        """One token if there is one."""
        self.tokens = min(self.burst, self.tokens + (now - self._at) * self.rate)
        self._at = now
        if self.tokens >= 1.0:
            self.tokens -= 1.0
            return True
        return False


class RemoteTable:
    """The remote resources heard in beacons, each with the time it was last heard."""

    def __init__(self, lost_after: float = LOST_AFTER, max_entries: int = MAX_REMOTE) -> None:
        self.lost_after = lost_after
        self.max_entries = max_entries
        self._last: Dict[str, float] = {}
        self._first: Dict[str, float] = {}
        self._resource: Dict[str, Resource] = {}
        self._lock = threading.Lock()

    def heard(self, key: str, now: float) -> Optional[Resource]:
        """A beacon on ``key`` at ``now``: the resource if it is new, None if already known.
        KeyMappingError for a key that declares nothing (the caller logs it once), and for a
        new key when the table is full."""
        with self._lock:
            if key in self._last:
                self._last[key] = now
                return None
        resource = parse_discovery_key(key)
        with self._lock:
            if key in self._last:
                self._last[key] = now
                return None
            if len(self._last) >= self.max_entries:
                raise TableFull(f"more than {self.max_entries} remote resources: "
                                f"ignoring [{key}]")
            self._last[key] = now
            self._first[key] = now
            self._resource[key] = resource
        return resource

    def expire(self, now: float) -> List[Resource]:
        """The resources silent for longer than ``lost_after``, removed."""
        with self._lock:
            lost = [k for k, t in self._last.items() if now - t > self.lost_after]
            for key in lost:
                del self._last[key]
                del self._first[key]
            return [self._resource.pop(key) for key in lost]

    def resources(self) -> FrozenSet[Resource]:
        with self._lock:
            return frozenset(self._resource.values())

    def first_heard(self) -> Dict[Tuple[str, str, str], float]:
        """When each remote topic or service (name, type, md5sum) was first heard, by any
        of the beacons that name it, since it was last lost."""
        with self._lock:
            out: Dict[Tuple[str, str, str], float] = {}
            for key, resource in self._resource.items():
                first = self._first[key]
                topic = resource.topic
                if first < out.get(topic, float("inf")):
                    out[topic] = first
            return out

    def __len__(self) -> int:
        with self._lock:
            return len(self._last)

    def clear(self) -> None:
        with self._lock:
            self._last.clear()
            self._first.clear()
            self._resource.clear()


class Declarations:
    """The beacons this bridge sends: each key once when declared, then every period."""

    def __init__(self, namespace: str, period: float = BEACON_PERIOD) -> None:
        self.namespace = namespace
        self.period = period
        self._next: Dict[str, float] = {}

    def key(self, resource: Resource) -> str:
        return discovery_key(resource.kind, resource.name, resource.type, resource.md5sum,
                             self.namespace)

    def update(self, resources: FrozenSet[Resource] | Set[Resource], now: float) -> None:
        """Declare exactly ``resources`` from now on (new ones are due at once)."""
        wanted = {self.key(r) for r in resources}
        for key in list(self._next):
            if key not in wanted:
                del self._next[key]
        for key in wanted:
            self._next.setdefault(key, now)

    def due(self, now: float) -> List[str]:
        """The keys to send now; each is then due again one period later."""
        keys = [k for k, t in self._next.items() if t <= now]
        for key in keys:
            self._next[key] = now + self.period
        return sorted(keys)

    def next_due(self) -> Optional[float]:
        return min(self._next.values()) if self._next else None

    def keys(self) -> List[str]:
        return sorted(self._next)
