"""ROS time for nodes: rospy's Time/Duration, the node clock, sleep, Rate and Timer.

The node clock is wall-clock time unless the node runs with ``/use_sim_time`` true; then it
follows the ``rosgraph_msgs/Clock`` messages on ``/clock`` and reads 0 until the first one
arrives (as rospy does). Everything that waits for time to pass (``sleep``, ``Rate``,
``Timer``) waits on one condition variable that is notified when simulated time moves, when a
timer is shut down and when the node shuts down, so nothing polls the clock in a busy loop
and every wait is bounded.
"""

from __future__ import annotations

import threading
import time
from typing import Any, Callable, Union

from minros import node
from minros.exceptions import (
    ROSInitException,
    ROSInterruptException,
    ROSTimeMovedBackwardsException,
)
from minros.msgs import Duration as _MsgDuration
from minros.msgs import Time as _MsgTime

__all__ = [
    "Duration",
    "Rate",
    "Time",
    "Timer",
    "TimerEvent",
    "get_rostime",
    "get_time",
    "is_wallclock",
    "sleep",
]

#: Upper bound on a single wait, so a missed notification costs at most this much latency.
_MAX_WAIT = 0.5


class Duration(_MsgDuration):
    """A span of ROS time (signed seconds + nanoseconds); rospy.Duration."""

    __slots__ = ()

    def __init__(self, secs: Union[int, float] = 0, nsecs: int = 0) -> None:
        super().__init__(secs, nsecs)

    def __repr__(self) -> str:
        return f"rospy.Duration[{self.to_nsec()}]"


class Time(_MsgTime):
    """A point in ROS time (seconds + nanoseconds since the epoch); rospy.Time."""

    __slots__ = ()

    def __init__(self, secs: Union[int, float] = 0, nsecs: int = 0) -> None:
        super().__init__(secs, nsecs)

    def __repr__(self) -> str:
        return f"rospy.Time[{self.to_nsec()}]"

    @staticmethod
    def now() -> Time:
        """The node's current time: wall clock, or the simulated clock from /clock."""
        return get_rostime()

    @classmethod
    def from_seconds(cls, float_secs: float) -> Time:
        """Old name of ``from_sec``, kept because old scripts call it."""
        return cls.from_sec(float_secs)


# --------------------------------------------------------------------------- the node clock

class _Clock:
    """The node-wide clock state, guarded by one condition variable."""

    def __init__(self) -> None:
        self.cond = threading.Condition(threading.Lock())
        self.initialized = False
        #: None = wall clock; otherwise the last simulated time received on /clock.
        self.sim_time: Time | None = None

    def notify(self) -> None:
        with self.cond:
            self.cond.notify_all()


_clock = _Clock()


_node_is_shutdown = node.is_shutdown


def _set_rostime(t: _MsgTime) -> None:
    """Move the simulated clock to ``t`` and wake every waiter (called per /clock message)."""
    if not isinstance(t, _MsgTime):
        raise ValueError(f"must be Time instance: {t.__class__}")
    value = t if isinstance(t, Time) else Time(t.secs, t.nsecs)
    with _clock.cond:
        _clock.sim_time = value
        _clock.cond.notify_all()


def _switch_to_wallclock() -> None:
    """Leave simulated time (tests, and nodes that stop using /clock)."""
    with _clock.cond:
        _clock.sim_time = None
        _clock.cond.notify_all()


def _set_initialized(value: bool) -> None:
    _clock.initialized = value


def is_rostime_initialized() -> bool:
    return _clock.initialized


def is_wallclock() -> bool:
    """Whether the node clock is the wall clock (i.e. not simulated)."""
    return _clock.sim_time is None


def get_rostime() -> Time:
    """The node's current time as a :class:`Time` (needs ``init_node``, as in rospy)."""
    if not _clock.initialized:
        raise ROSInitException("time is not initialized. Have you called init_node()?")
    sim = _clock.sim_time
    if sim is not None:
        return sim
    return _wall_now()


def _wall_now() -> Time:
    # integer arithmetic on time_ns() avoids float rounding of the nanoseconds
    ns = time.time_ns()
    return Time(ns // 1_000_000_000, ns % 1_000_000_000)


def get_time() -> float:
    """The node's current time in float seconds (``time.time()`` format)."""
    return get_rostime().to_sec()


def on_clock(msg: Any) -> None:
    """A ``rosgraph_msgs/Clock`` from /clock (``init_node`` subscribes it on simulated time)."""
    _set_rostime(msg.clock)


def _on_node_shutdown(*_args) -> None:
    _clock.notify()


def start_node_time(use_sim_time: bool) -> None:
    """Called by ``init_node``: start the node clock, at 0 on simulated time until the first
    /clock message arrives (as rospy does)."""
    node.add_shutdown_hook(_on_node_shutdown)
    if use_sim_time:
        _set_rostime(Time(0, 0))
    _clock.initialized = True


# rospy.rostime's internal names, which some tests and tools call directly
set_rostime_initialized = _set_initialized
switch_to_wallclock = _switch_to_wallclock


def get_rostime_cond() -> threading.Condition:
    """The condition notified whenever the node clock moves (rospy.rostime internal API)."""
    return _clock.cond


def wallsleep(duration: float) -> None:
    """Sleep in wall-clock time regardless of simulated time (rospy.rostime.wallsleep)."""
    time.sleep(duration)


# --------------------------------------------------------------------------- sleeping

def _to_duration(value: Union[float, int, _MsgDuration]) -> Duration:
    if isinstance(value, _MsgDuration):
        return value if isinstance(value, Duration) else Duration(value.secs, value.nsecs)
    return Duration.from_sec(float(value))


def _wait_wall(seconds: float, stop: Callable[[], bool] | None) -> None:
    """Wait ``seconds`` of wall time, returning early on node shutdown or when ``stop()``."""
    if seconds <= 0:
        return
    if stop is None:
        node.wait_for_shutdown(seconds)
        return
    deadline = time.monotonic() + seconds
    with _clock.cond:
        while not _node_is_shutdown() and not (stop is not None and stop()):
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return
            _clock.cond.wait(min(remaining, _MAX_WAIT))


def _wait_sim(duration: Duration, stop: Callable[[], bool] | None) -> None:
    """Wait until simulated time advanced by ``duration``; raise if it jumps backwards."""
    def stopped() -> bool:
        return _node_is_shutdown() or (stop is not None and stop())

    with _clock.cond:
        start = _clock.sim_time
        # rospy: a simulated clock still at 0 has not started yet; wait for the first tick
        while start is not None and start.is_zero() and not stopped():
            _clock.cond.wait(_MAX_WAIT)
            start = _clock.sim_time
        if start is None:  # switched back to wall clock while waiting
            return
        target = start + duration
        while not stopped():
            now = _clock.sim_time
            if now is None or now >= target or now < start:
                break
            _clock.cond.wait(_MAX_WAIT)
        now = _clock.sim_time
    if now is not None and now < start:
        raise ROSTimeMovedBackwardsException((start - now).to_sec())


#: per thread: whether it slept once already after the node shut down (wall clock)
_after_shutdown = threading.local()


def _sleep(duration: Union[float, int, _MsgDuration], stop: Callable[[], bool] | None = None) -> None:
    d = _to_duration(duration)
    if is_wallclock():
        # rospy's wall sleep raises nothing (a time.sleep), so the tutorial's `while not
        # rospy.is_shutdown(): ... rate.sleep()` ends quietly on Ctrl-C, wherever in the loop
        # the signal lands: a sleep the shutdown cuts short returns, and so does the first one
        # a thread begins after it, which sleeps its time as rospy's (code that publishes a
        # last message at shutdown sleeps so it goes out). A second one raises, so a loop that
        # never looks at is_shutdown() ends (rospy's runs on, deaf to Ctrl-C).
        if _node_is_shutdown():
            if getattr(_after_shutdown, "slept", False):
                raise ROSInterruptException("ROS shutdown request")
            _after_shutdown.slept = True
            if stop is None:
                time.sleep(max(d.to_sec(), 0.0))
            return
        _wait_wall(d.to_sec(), stop)
        return
    _wait_sim(d, stop)
    if _node_is_shutdown():
        raise ROSInterruptException("ROS shutdown request")


def sleep(duration: Union[float, int, _MsgDuration]) -> None:
    """Sleep for ``duration`` (seconds or Duration) of ROS time; negative returns at once.

    Raises ROSInterruptException when the node shuts down meanwhile on simulated time (on the
    wall clock, as rospy, the sleep returns; the second a thread begins after shutdown raises),
    and
    ROSTimeMovedBackwardsException when simulated time jumps backwards.
    """
    _sleep(duration)


class Rate:
    """Sleep in a loop at ``hz``, accounting for the time spent between sleeps (rospy.Rate)."""

    def __init__(self, hz: float, reset: bool = False) -> None:
        self.last_time: _MsgTime = get_rostime()
        self.sleep_dur = Duration(0, int(1e9 / hz))
        self._reset = reset

    def _remaining(self, curr_time: _MsgTime) -> Duration:
        if self.last_time > curr_time:  # time went backwards: restart the cycle from now
            self.last_time = curr_time
        elapsed = curr_time - self.last_time
        return _to_duration(self.sleep_dur - elapsed)

    def remaining(self) -> Duration:
        """Time left until the end of the current cycle."""
        return self._remaining(get_rostime())

    def sleep(self, _stop: Callable[[], bool] | None = None) -> None:
        """Sleep until the end of the current cycle.

        Raises ROSInterruptException on shutdown, ROSTimeMovedBackwardsException when simulated
        time moves backwards (unless ``reset``, which restarts the cycle instead).
        """
        curr_time = get_rostime()
        try:
            _sleep(self._remaining(curr_time), _stop)
        except ROSTimeMovedBackwardsException:
            if not self._reset:
                raise
            self.last_time = get_rostime()
            return
        self.last_time = self.last_time + self.sleep_dur
        # fell more than two cycles behind (slow loop, time jump): catch up instead of bursting
        if curr_time - self.last_time > self.sleep_dur * 2:
            self.last_time = curr_time


class TimerEvent:
    """What a Timer callback is told about the current and the previous call."""

    def __init__(self, last_expected: Any, last_real: Any, current_expected: Any, current_real: Any, last_duration: Any) -> None:
        #: when the previous callback should have run (None on the first call)
        self.last_expected = last_expected
        #: when the previous callback actually ran (None on the first call)
        self.last_real = last_real
        #: when this callback should run
        self.current_expected = current_expected
        #: when this callback actually runs
        self.current_real = current_real
        #: wall-clock seconds the previous callback took (None on the first call)
        self.last_duration = last_duration

    def __repr__(self) -> str:
        return (f"TimerEvent(last_expected={self.last_expected!r}, last_real={self.last_real!r}, current_expected={self.current_expected!r}, current_real={self.current_real!r}, "
                f"last_duration={self.last_duration!r})")


class Timer(threading.Thread):
    """Call ``callback(TimerEvent)`` every ``period`` (a Duration) in its own thread."""

    def __init__(self, period: _MsgDuration, callback: Callable[[TimerEvent], None],
                 oneshot: bool = False, reset: bool = False) -> None:
        super().__init__(name="Timer")
        self._period = period
        self._callback = callback
        self._oneshot = oneshot
        self._reset = reset
        self._shutdown = False
        self.daemon = True
        self.start()

    def shutdown(self) -> None:
        """Stop calling the callback (a callback already running finishes)."""
        self._shutdown = True
        _clock.notify()

    def _stopped(self) -> bool:
        return self._shutdown

    def run(self) -> None:
        period = _to_duration(self._period)
        rate = Rate(1.0 / period.to_sec(), reset=self._reset)
        current_expected = get_rostime() + period
        last_expected = last_real = last_duration = None
        while not _node_is_shutdown() and not self._shutdown:
            try:
                rate.sleep(self._stopped)
            except ROSInterruptException:
                if _node_is_shutdown():
                    break
                raise
            if self._shutdown:
                break
            current_real = get_rostime()
            started = time.time()
            self._callback(TimerEvent(last_expected, last_real, current_expected, current_real,
                                      last_duration))
            if self._oneshot:
                break
            last_duration = time.time() - started
            last_expected, last_real = current_expected, current_real
            current_expected = current_expected + period
