"""What one client is waiting to receive: bounded, so a slow client never holds the graph back.

A client's :class:`Outbox` has one *slot* per subscription, each a bounded queue of the latest
messages (oldest dropped past ``maxlen`` messages or ``max_bytes``; the newest is always kept),
and one control queue for replies (service responses, status, advertisements) that are never
dropped silently: when it overflows the client is not reading, and ``put_control`` says so, so
the server closes that client. ROS callbacks only append here (no I/O, no encoding); the
client's writer thread takes items in turn (control first, then the slots round-robin), obeying
each slot's ``min_interval`` (rosbridge's ``throttle_rate``), and does the encoding and the
send. No sockets: tests drive it directly.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from typing import Any, Callable, Deque, Dict, Hashable, Optional, Tuple

#: control items a client may owe before it counts as not reading
MAX_CONTROL_ITEMS = 10_000
#: bytes of control items a client may owe before it counts as not reading
MAX_CONTROL_BYTES = 64 << 20


class Slot:
    """The latest messages of one subscription of one client."""

    __slots__ = ("key", "render", "maxlen", "max_bytes", "min_interval", "items", "bytes",
                 "next_due", "dropped", "sent")

    def __init__(self, key: Hashable, render: Callable[[Any], Any], maxlen: int,
                 max_bytes: int, min_interval: float) -> None:
        self.key = key
        self.render = render
        self.maxlen = max(1, maxlen)
        self.max_bytes = max_bytes
        self.min_interval = min_interval
        self.items: Deque[Tuple[Any, int]] = deque()
        self.bytes = 0
        self.next_due = 0.0
        self.dropped = 0
        self.sent = 0


class Outbox:
    """Bounded per-client queues; many producers, one consumer (the client's writer)."""

    def __init__(self, max_control_items: int = MAX_CONTROL_ITEMS,
                 max_control_bytes: int = MAX_CONTROL_BYTES,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._cond = threading.Condition(threading.Lock())
        self._control: Deque[Tuple[Any, int]] = deque()
        self._control_bytes = 0
        self._slots: Dict[Hashable, Slot] = {}
        self._order: Deque[Hashable] = deque()  # round-robin order of the slots
        self._closed = False
        self.max_control_items = max_control_items
        self.max_control_bytes = max_control_bytes
        self._clock = clock

    # -- producers -------------------------------------------------------------------------

    def put_control(self, item: Any, size: int = 0) -> bool:
        """Queue a reply; False (item not queued) when the client owes too much already."""
        with self._cond:
            if self._closed:
                return True
            if (len(self._control) >= self.max_control_items
                    or self._control_bytes + size > self.max_control_bytes and self._control):
                return False
            self._control.append((item, size))
            self._control_bytes += size
            self._cond.notify()
            return True

    def open_slot(self, key: Hashable, render: Callable[[Any], Any], maxlen: int = 1,
                  max_bytes: int = 32 << 20, min_interval: float = 0.0) -> None:
        """Create (or reconfigure) the slot ``key``; ``render(item)`` makes the frame to send."""
        with self._cond:
            slot = self._slots.get(key)
            if slot is None:
                self._slots[key] = Slot(key, render, maxlen, max_bytes, min_interval)
                self._order.append(key)
            else:
                slot.render = render
                slot.maxlen = max(1, maxlen)
                slot.max_bytes = max_bytes
                slot.min_interval = min_interval
                self._trim(slot)
            self._cond.notify()

    def close_slot(self, key: Hashable) -> None:
        with self._cond:
            if self._slots.pop(key, None) is not None:
                self._order.remove(key)

    def put(self, key: Hashable, item: Any, size: int = 0) -> None:
        """Queue a message for slot ``key`` (dropped when the slot is gone)."""
        with self._cond:
            slot = self._slots.get(key)
            if slot is None or self._closed:
                return
            slot.items.append((item, size))
            slot.bytes += size
            self._trim(slot)
            self._cond.notify()

    @staticmethod
    def _trim(slot: Slot) -> None:
        items = slot.items
        while len(items) > slot.maxlen or (slot.bytes > slot.max_bytes and len(items) > 1):
            _item, size = items.popleft()
            slot.bytes -= size
            slot.dropped += 1

    # -- the consumer ----------------------------------------------------------------------

    def get(self, timeout: Optional[float] = None) -> Optional[Tuple[Optional[Slot], Any]]:
        """The next ``(slot, item)`` to send (slot None for control items); None on timeout
        or once closed."""
        deadline = None if timeout is None else self._clock() + timeout
        with self._cond:
            while not self._closed:
                if self._control:
                    item, size = self._control.popleft()
                    self._control_bytes -= size
                    return None, item
                now = self._clock()
                wait = None if deadline is None else deadline - now
                for _ in range(len(self._order)):
                    key = self._order[0]
                    self._order.rotate(-1)
                    slot = self._slots[key]
                    if not slot.items:
                        continue
                    if slot.next_due > now:
                        pause = slot.next_due - now
                        wait = pause if wait is None else min(wait, pause)
                        continue
                    item, size = slot.items.popleft()
                    slot.bytes -= size
                    slot.sent += 1
                    if slot.min_interval:
                        slot.next_due = now + slot.min_interval
                    return slot, item
                if wait is not None and wait <= 0:
                    return None
                self._cond.wait(wait)
            return None

    def close(self) -> None:
        with self._cond:
            self._closed = True
            self._control.clear()
            self._slots.clear()
            self._order.clear()
            self._cond.notify_all()

    @property
    def closed(self) -> bool:
        return self._closed

    def stats(self) -> Dict[Hashable, Tuple[int, int, int]]:
        """``{slot key: (queued, sent, dropped)}``."""
        with self._cond:
            return {k: (len(s.items), s.sent, s.dropped) for k, s in self._slots.items()}
