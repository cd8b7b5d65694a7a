"""message_filters for minros: chainable message filters and time synchronizers.

The ``message_filters`` stand-in re-exports this module. A filter has callbacks
(:meth:`SimpleFilter.registerCallback`) that it calls with its output; filters chain by
registering one filter's input method as another's callback. Outputs equal ROS 1's
(ros_comm 1.15) for the same input sequence: same sets, same order, same drops.
"""

from __future__ import annotations

import threading
from functools import reduce
from typing import Any, Callable, Dict, List, Sequence, Tuple

import minros

__all__ = ["SimpleFilter", "Subscriber", "Cache", "TimeSynchronizer",
           "ApproximateTimeSynchronizer"]

_HEADERLESS_WARNING = ("Cannot use message filters with non-stamped messages. Use the "
                       "'allow_headerless' constructor option to auto-assign ROS time to "
                       "headerless messages.")


def _stamp_of(msg: Any, allow_headerless: bool) -> Any:
    """``msg.header.stamp``; the current ROS time for headerless messages if allowed, else None."""
    header = getattr(msg, "header", None)
    stamp = getattr(header, "stamp", None) if header is not None else None
    if stamp is not None:
        return stamp
    if not allow_headerless:
        minros.logwarn(_HEADERLESS_WARNING)
        return None
    return minros.Time.now()


def _is_wallclock() -> bool:
    from minros.client import rostime  # is simulated time (/clock) in use?

    return rostime.is_wallclock()


class SimpleFilter:
    """Base of all filters: a list of callbacks called with the filter's output."""

    def __init__(self) -> None:
        self.callbacks: Dict[int, Tuple[Callable, tuple]] = {}

    def registerCallback(self, cb: Callable, *args: Any) -> int:
        """Call ``cb(*outputs, *args)`` on each output; returns the connection number."""
        conn = len(self.callbacks)
        self.callbacks[conn] = (cb, args)
        return conn

    def signalMessage(self, *msg: Any) -> None:
        for cb, args in list(self.callbacks.values()):
            cb(*(msg + args))


class Subscriber(SimpleFilter):
    """A ROS subscription as the source of a filter chain (rospy.Subscriber's arguments)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        SimpleFilter.__init__(self)
        self.topic = args[0] if args else kwargs.get("name")
        kwargs["callback"] = self.callback
        self.sub = minros.Subscriber(*args, **kwargs)

    def callback(self, msg: Any) -> None:
        self.signalMessage(msg)

    def getTopic(self) -> str:
        return self.topic

    def __getattr__(self, key: str) -> Any:
        # everything else is the subscriber's (unregister, get_num_connections, ...)
        if key == "sub":
            raise AttributeError(key)
        return getattr(self.sub, key)


class Cache(SimpleFilter):
    """The last ``cache_size`` messages of its input, queryable by time; passes them on."""

    def __init__(self, f: SimpleFilter, cache_size: int = 1, allow_headerless: bool = False) -> None:
        SimpleFilter.__init__(self)
        self.connectInput(f)
        self.cache_size = cache_size
        self.cache_msgs: List[Any] = []
        self.cache_times: List[Any] = []
        self.allow_headerless = allow_headerless

    def connectInput(self, f: SimpleFilter) -> None:
        self.incoming_connection = f.registerCallback(self.add)

    def add(self, msg: Any) -> None:
        stamp = _stamp_of(msg, self.allow_headerless)
        if stamp is None:
            return
        # kept in arrival order (as ROS 1 does), the oldest dropped beyond cache_size
        self.cache_times.append(stamp)
        self.cache_msgs.append(msg)
        if len(self.cache_msgs) > self.cache_size:
            del self.cache_msgs[0]
            del self.cache_times[0]
        self.signalMessage(msg)

    def getInterval(self, from_stamp: Any, to_stamp: Any) -> List[Any]:
        """Messages stamped within ``[from_stamp, to_stamp]``."""
        assert from_stamp <= to_stamp
        return [m for m, t in zip(self.cache_msgs, self.cache_times) if from_stamp <= t <= to_stamp]

    def getElemAfterTime(self, stamp: Any) -> Any:
        """The first cached message stamped at or after ``stamp`` (None if none)."""
        for m, t in zip(self.cache_msgs, self.cache_times):
            if t >= stamp:
                return m
        return None

    def getElemBeforeTime(self, stamp: Any) -> Any:
        """The last cached message stamped at or before ``stamp`` (None if none)."""
        found = None
        for m, t in zip(self.cache_msgs, self.cache_times):
            if t <= stamp:
                found = m
        return found

    def getLatestTime(self) -> Any:
        return self.cache_times[-1] if self.cache_times else None

    def getLastestTime(self) -> Any:
        """Old misspelt name of :meth:`getLatestTime`, kept for existing code."""
        return self.getLatestTime()

    def getOldestTime(self) -> Any:
        return self.cache_times[0] if self.cache_times else None

    def getLast(self) -> Any:
        latest = self.getLatestTime()
        return None if latest is None else self.getElemAfterTime(latest)


class TimeSynchronizer(SimpleFilter):
    """Outputs one message per input when all inputs have a message with the same stamp.

    Each input keeps at most ``queue_size`` messages (by stamp, the oldest dropped); the
    callback gets them in input order. ``reset`` clears an input's queue when simulated time
    jumps back.
    """

    def __init__(self, fs: Sequence[SimpleFilter], queue_size: int, reset: bool = False) -> None:
        SimpleFilter.__init__(self)
        self.lock = threading.Lock()
        self.connectInput(fs)
        self.queue_size = queue_size
        self.enable_reset = reset

    def connectInput(self, fs: Sequence[SimpleFilter]) -> None:
        self.queues: List[Dict[Any, Any]] = [{} for _ in fs]
        self.latest_stamps = [minros.Time(0) for _ in fs]
        self.input_connections = [f.registerCallback(self.add, q, i)
                                  for i, (f, q) in enumerate(zip(fs, self.queues))]

    def _note_time(self, my_queue: Dict[Any, Any], index: int | None) -> Any:
        """Simulated-time reset bookkeeping: the time now when resets apply (``reset`` under
        simulated time), else None, without reading the clock."""
        if not self.enable_reset or _is_wallclock():
            return None
        now = minros.Time.now()
        if index is not None:
            if now < self.latest_stamps[index]:
                minros.logdebug("Detected jump back in time. Clearing message filter queue")
                my_queue.clear()
            self.latest_stamps[index] = now
        return now

    def add(self, msg: Any, my_queue: Dict[Any, Any], my_queue_index: int | None = None) -> None:
        with self.lock:
            now = self._note_time(my_queue, my_queue_index)
            my_queue[msg.header.stamp] = msg
            while len(my_queue) > self.queue_size:
                del my_queue[min(my_queue)]
            if now is not None and max(self.latest_stamps) != now:
                return
            common = reduce(set.intersection, [set(q) for q in self.queues])
            for stamp in sorted(common):
                msgs = [q[stamp] for q in self.queues]
                self.signalMessage(*msgs)
                for q in self.queues:
                    del q[stamp]


class ApproximateTimeSynchronizer(TimeSynchronizer):
    """Outputs one message per input when their stamps lie within ``slop`` seconds.

    On each arrival it looks, in the other inputs, for messages within ``slop`` of the new one
    and outputs the first combination (candidates ordered by closeness, earlier inputs
    varying slowest) whose stamps span less than ``slop``; the outputs are removed.
    """

    def __init__(self, fs: Sequence[SimpleFilter], queue_size: int, slop: float,
                 allow_headerless: bool = False, reset: bool = False) -> None:
        TimeSynchronizer.__init__(self, fs, queue_size)
        self.slop = minros.Duration.from_sec(slop)
        self.allow_headerless = allow_headerless
        self.last_added = minros.Time()
        self.enable_reset = reset

    def add(self, msg: Any, my_queue: Dict[Any, Any], my_queue_index: int | None = None) -> None:
        stamp = _stamp_of(msg, self.allow_headerless)
        if stamp is None:
            return
        with self.lock:
            resetting = self._note_time(my_queue, my_queue_index) is not None
            my_queue[stamp] = msg
            now = minros.Time.now()  # read again after the reset check, as ROS 1 does
            if now < self.last_added:
                minros.loginfo("ApproximateTimeSynchronizer: Detected jump back in time. "
                               "Clearing buffer.")
                for q in self.queues:
                    q.clear()
            self.last_added = now
            while len(my_queue) > self.queue_size:
                del my_queue[min(my_queue)]
            if resetting and max(self.latest_stamps) != now:
                return
            match = self._find_match(stamp, my_queue_index)
            if match is None:
                return
            msgs = [q[t] for q, t in zip(self.queues, match)]
            self.signalMessage(*msgs)
            for q, t in zip(self.queues, match):
                del q[t]

    def _find_match(self, stamp: Any, index: int | None) -> List[Any] | None:
        """The stamps (one per input) to output together, or None."""
        slop = self.slop.to_nsec()
        center = stamp.to_nsec()
        others = [i for i in range(len(self.queues)) if i != index]
        candidates: List[List[Tuple[Any, int]]] = []
        for i in others:
            near = [(s, ns) for s in self.queues[i] if abs((ns := s.to_nsec()) - center) <= slop]
            if not near:
                return None
            near.sort(key=lambda c: abs(c[1] - center))  # stable: ties keep arrival order
            candidates.append(near)
        if index is not None and stamp not in self.queues[index]:
            return None  # the new message was the oldest of a full queue and is gone already
        chosen = match_within(candidates, slop, center if index is not None else None)
        if chosen is None:
            return None
        if index is not None:
            chosen.insert(index, stamp)
        return chosen


def match_within(candidates: List[List[Tuple[Any, int]]], slop: int,
                 fixed: int | None) -> List[Any] | None:
    """First pick (one ``(stamp, nsec)`` per list, in itertools.product order) whose nanosecond
    values, with ``fixed`` if given, span less than ``slop``; its stamps, or None.

    A depth-first walk in product order that abandons a prefix as soon as its span reaches
    ``slop`` (adding stamps never shrinks a span), so it returns the same pick as trying every
    combination in order without trying most of them.
    """
    picks: List[Any] = []
    depth = len(candidates)

    def walk(level: int, low: int | None, high: int | None) -> bool:
        if level == depth:
            return low is None or high - low < slop  # a lone fixed stamp spans 0
        for stamp, ns in candidates[level]:
            lo = ns if low is None or ns < low else low
            hi = ns if high is None or ns > high else high
            if hi - lo >= slop:
                continue
            picks.append(stamp)
            if walk(level + 1, lo, hi):
                return True
            picks.pop()
        return False

    if walk(0, fixed, fixed):
        return picks
    return None
