"""Discovery state of zenoh-bridge-ros1's beacons, without sockets (times are arguments).

A bridge declares each ROS resource it bridges by sending an empty sample on the resource's
discovery key every second (``BEACON_PERIOD``); a resource whose beacon has been silent for
three periods (``LOST_AFTER``) is lost (zenoh-plugin-ros1 ``aloha_declaration.rs``,
``aloha_subscription.rs``; its check runs once per 3 s, so it notices a loss after 3 to 6 s,
this table after 3 s plus the caller's tick).

``RemoteTable`` is what a bridge heard; ``Declarations`` what it sends and when; ``OnceLog``
keeps a misbehaving peer to one log line per distinct fault.
"""

from __future__ import annotations

import threading
from typing import Callable, Dict, FrozenSet, List, Optional, Set

from minros.zenoh.keys import KeyMappingError, Resource, discovery_key, parse_discovery_key

__all__ = ["BEACON_PERIOD", "LOST_AFTER", "Declarations", "OnceLog", "RemoteTable"]

BEACON_PERIOD = 1.0
LOST_AFTER = 3.0 * BEACON_PERIOD
#: bound on the resources remembered from peers (a peer inventing keys cannot grow it further)
MAX_REMOTE = 20000


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


class RemoteTable:
    """The remote resources heard in beacons, each with the time it was last heard."""

    def __init__(self, lost_after: float = LOST_AFTER, max_entries: int = MAX_REMOTE) -> None:
        self.lost_after = lost_after
        self.max_entries = max_entries
        self._last: Dict[str, float] = {}
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
                raise KeyMappingError(f"more than {self.max_entries} remote resources: "
                                      f"ignoring [{key}]")
            self._last[key] = now
            self._resource[key] = resource
        return resource

    def expire(self, now: float) -> List[Resource]:
        """The resources silent for longer than ``lost_after``, removed."""
        with self._lock:
            lost = [k for k, t in self._last.items() if now - t > self.lost_after]
            for key in lost:
                del self._last[key]
            return [self._resource.pop(key) for key in lost]

    def resources(self) -> FrozenSet[Resource]:
        with self._lock:
            return frozenset(self._resource.values())

    def clear(self) -> None:
        with self._lock:
            self._last.clear()
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
