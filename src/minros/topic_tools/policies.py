"""What passes: the throttle's and drop's decisions and the mux's selection, without I/O.

Times are seconds (floats) from whatever clock the node uses (ROS time or wall time).
"""

from __future__ import annotations

import collections
from typing import Deque, List, Optional, Tuple

NONE_TOPIC = "__none"


class MessageThrottle:
    """At most one message per ``1 / rate`` seconds; the first one passes."""

    def __init__(self, rate: float) -> None:
        if not rate > 0:
            raise ValueError(f"MSGS_PER_SEC must be a positive number, not {rate}")
        self.period = 1.0 / rate
        self.last: Optional[float] = None

    def accept(self, now: float) -> bool:
        if self.last is not None and now < self.last:
            self.last = now  # time went backwards (a bag restarted): start a new period
        if self.last is None or now - self.last >= self.period:
            self.last = now
            return True
        return False


class ByteThrottle:
    """Keeps the bytes sent in the last ``window`` seconds below ``bytes_per_sec * window``."""

    def __init__(self, bytes_per_sec: float, window: float) -> None:
        if not bytes_per_sec > 0 or not window > 0:
            raise ValueError("BYTES_PER_SEC and WINDOW must be positive numbers, not "
                             f"{bytes_per_sec} and {window}")
        self.bytes_per_sec = bytes_per_sec
        self.window = window
        self.sent: Deque[Tuple[float, int]] = collections.deque()
        self.total = 0

    def accept(self, now: float, size: int) -> bool:
        while self.sent and (now - self.sent[0][0] > self.window or now < self.sent[0][0]):
            self.total -= self.sent.popleft()[1]
        if (self.total + size) / self.window <= self.bytes_per_sec or not self.sent:
            self.sent.append((now, size))
            self.total += size
            return True
        return False


class Dropper:
    """Drops ``x`` out of every ``y`` messages: the first ``x`` of each group of ``y``."""

    def __init__(self, x: int, y: int) -> None:
        if x < 0 or y <= 0 or x > y:
            raise ValueError(f"X and Y must be whole numbers with 0 <= X <= Y and Y > 0, not "
                             f"{x} and {y}")
        self.x, self.y = x, y
        self.count = 0

    def accept(self) -> bool:
        passes = self.count >= self.x
        self.count = (self.count + 1) % self.y
        return passes


class MuxTable:
    """The mux's inputs (resolved names, in order) and the one selected (None: no input)."""

    def __init__(self, topics: List[str], initial: Optional[str] = None) -> None:
        self.topics: List[str] = []
        for topic in topics:
            if topic not in self.topics:
                self.topics.append(topic)
        if initial == NONE_TOPIC:
            self.selected: Optional[str] = None
        elif initial:
            if initial not in self.topics:
                raise ValueError(f"initial_topic {initial} is not one of the inputs "
                                 f"{self.topics}")
            self.selected = initial
        else:
            self.selected = self.topics[0] if self.topics else None

    def select(self, topic: str) -> Tuple[bool, str]:
        """(done, previous topic or ''); ``__none`` selects no input."""
        previous = self.selected or ""
        if topic == NONE_TOPIC:
            self.selected = None
            return True, previous
        if topic in self.topics:
            self.selected = topic
            return True, previous
        return False, previous

    def add(self, topic: str) -> bool:
        if topic in self.topics:
            return False
        self.topics.append(topic)
        return True

    def delete(self, topic: str) -> bool:
        if topic not in self.topics:
            return False
        self.topics.remove(topic)
        if self.selected == topic:
            self.selected = None
        return True


def parse_float(text: str, what: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"{what} must be a number, not {text!r}") from None


def parse_int(text: str, what: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise ValueError(f"{what} must be a whole number, not {text!r}") from None


