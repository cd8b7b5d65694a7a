"""The publisher's queue of one connection, without I/O: what waits to be sent, how much of it is
kept, and how long a publisher a whole queue ahead waits for room. Both stream transports use it
(``sender.QueuedSender``, under ``TCPROSSender`` and ``ShmSender``), so TCPROS and MINROSSHM
drop and back off by the same rules:

* **bounded, oldest dropped**: ``limit`` items at most (the publication's queue_size; 0 is
  unbounded, as rospy's queue_size=0); a new item beyond it drops the oldest, so a slow
  subscriber always gets the latest messages;
* **never half a frame**: the item being sent is not in the queue (the sender's ``out``), so
  dropping the oldest never cuts a frame;
* **back-off**: a publisher that finds the queue full waits for room for as long as its frame
  takes to send at BACKOFF_RATE bytes per second (at most BACKOFF_MAX, and not at all below
  BACKOFF_MIN) before it drops one: a loop publishing images faster than the wire would
  otherwise spin and take the CPU the sending side needs (6 ms for a 1920x1080 image, nothing
  for a small message);
* **synchronous**: ``limit`` None (queue_size=None) queues nothing for long: the publisher
  hands everything over before ``send`` returns, waiting at most SYNC_SEND_TIMEOUT for a
  subscriber that takes nothing.
"""

from __future__ import annotations

import collections
from typing import Any, Deque, Sequence, Tuple

__all__ = ["BACKOFF_BYTES", "BACKOFF_MAX", "BACKOFF_MIN", "BACKOFF_RATE", "SYNC_SEND_TIMEOUT",
           "SendQueue"]

#: a synchronous (queue_size=None) publisher waits at most this long for a slow subscriber
SYNC_SEND_TIMEOUT = 60.0
#: the back-off of a publisher a whole queue ahead: its frame's send time at this many bytes
#: per second (loopback's order), at most BACKOFF_MAX seconds, none below BACKOFF_MIN
BACKOFF_RATE = 1e9
BACKOFF_MAX = 0.01
BACKOFF_MIN = 50e-6
#: frames smaller than this never wait (BACKOFF_MIN's worth at BACKOFF_RATE)
BACKOFF_BYTES = int(BACKOFF_MIN * BACKOFF_RATE)
_NONE: Tuple[Any, ...] = ()


class SendQueue:
    """The items waiting on one connection (frames, or a transport's records of them)."""

    __slots__ = ("items", "limit", "sync", "dropped")

    def __init__(self, limit: int | None) -> None:
        self.items: Deque[Any] = collections.deque()
        #: 0: unbounded
        self.limit = limit or 0
        self.sync = limit is None
        #: items dropped so far (for tests and getBusInfo)
        self.dropped = 0

    def __len__(self) -> int:
        return len(self.items)

    def full(self) -> bool:
        """Whether a new item would drop the oldest."""
        return bool(self.limit) and len(self.items) >= self.limit

    @staticmethod
    def backoff(size: int) -> float:
        """Seconds a publisher that finds the queue full waits for room before dropping, for
        a frame of ``size`` bytes (0: do not wait)."""
        wait = size / BACKOFF_RATE
        return min(wait, BACKOFF_MAX) if wait >= BACKOFF_MIN else 0.0

    def put(self, item: Any) -> Sequence[Any]:
        """Queue ``item``; the oldest items the limit dropped to make room (usually none)."""
        items = self.items
        items.append(item)
        if not self.limit or len(items) <= self.limit:
            return _NONE
        dropped = []
        while len(items) > self.limit:
            dropped.append(items.popleft())
        self.dropped += len(dropped)
        return dropped

    def clear(self) -> None:
        self.items.clear()
