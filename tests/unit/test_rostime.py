"""minros.client.rostime: rospy's Time/Duration, the node clock, sleep, Rate, Timer and TimerEvent.

Most tests drive the *simulated* clock (``_set_rostime``, what a /clock message does) as a fake
clock: waits then end exactly when the test moves time, so nothing here depends on how fast
the machine is. A thread that must be blocked before time moves is detected by the clock's
condition variable itself (an event set as a thread starts waiting on it), not by sleeping.
"""

from __future__ import annotations

import threading
import time

import pytest

from minros.client import rostime
from minros.client.rostime import Duration, Rate, Time, Timer, TimerEvent
from minros.exceptions import (
    ROSInitException,
    ROSInterruptException,
    ROSTimeMovedBackwardsException,
)


class WatchedCondition(threading.Condition):
    """The clock's condition, telling the test when a thread starts waiting on it. The event is
    set before the wait releases the lock, and moving the clock takes the lock: a test that saw
    it can move the clock knowing the waiter is registered."""

    def __init__(self) -> None:
        super().__init__()
        self.waiting = threading.Event()

    def wait(self, timeout=None):
        self.waiting.set()
        return super().wait(timeout)


@pytest.fixture(autouse=True)
def watched_clock(monkeypatch):
    monkeypatch.setattr(rostime._clock, "cond", WatchedCondition())


@pytest.fixture
def clock():
    """A simulated node clock at t=100 s; restores the module's clock state afterwards."""
    saved = (rostime._clock.initialized, rostime._clock.sim_time)
    rostime._set_initialized(True)
    rostime._set_rostime(Time(100, 0))
    yield rostime
    rostime._clock.initialized, rostime._clock.sim_time = saved
    rostime._clock.notify()


@pytest.fixture
def wallclock():
    saved = (rostime._clock.initialized, rostime._clock.sim_time)
    rostime._set_initialized(True)
    rostime._switch_to_wallclock()
    yield rostime
    rostime._clock.initialized, rostime._clock.sim_time = saved


def wait_for_waiter(timeout: float = 5.0) -> None:
    """Until a thread (again) waits on the clock."""
    waiting = rostime._clock.cond.waiting
    assert waiting.wait(timeout), "no thread started waiting on the clock"
    waiting.clear()


def in_thread(fn):
    """Run ``fn`` in a thread; returns (thread, result dict with 'value' or 'error')."""
    result: dict = {}

    def run():
        try:
            result["value"] = fn()
        except BaseException as exc:  # noqa: BLE001 - reported to the test
            result["error"] = exc

    t = threading.Thread(target=run, daemon=True)
    t.start()
    return t, result


# ---------------------------------------------------------------------------- Time / Duration

def test_time_and_duration_are_rospy_types_over_msgs_types():
    from minros.msgs import Duration as MsgDuration
    from minros.msgs import Time as MsgTime

    t = Time(5, 500)
    assert isinstance(t, MsgTime) and (t.secs, t.nsecs) == (5, 500)
    assert repr(t) == "rospy.Time[5000000500]"
    d = Duration(-1, 5)
    assert isinstance(d, MsgDuration)
    assert repr(Duration(2)) == "rospy.Duration[2000000000]"
    assert Time.from_seconds(1.5) == Time(1, 500000000)
    assert Time.from_sec(2.25).to_nsec() == 2250000000
    assert (Time(5) - Time(3)).to_sec() == 2.0
    assert (Time(5) + Duration(1)) == Time(6)


def test_get_rostime_before_init_raises_like_rospy():
    saved = rostime._clock.initialized
    rostime._set_initialized(False)
    try:
        with pytest.raises(ROSInitException, match="time is not initialized"):
            rostime.get_rostime()
        with pytest.raises(ROSInitException):
            Time.now()
    finally:
        rostime._set_initialized(saved)


def test_wall_clock_now_tracks_time_time(wallclock):
    before = time.time()
    now = Time.now()
    after = time.time()
    assert isinstance(now, Time)
    assert before - 1e-6 <= now.to_sec() <= after + 1e-6
    assert rostime.is_wallclock()
    assert before - 1e-6 <= rostime.get_time() <= time.time() + 1e-6


# ---------------------------------------------------------------------------- simulated clock

def test_sim_clock_reads_last_clock_message(clock):
    assert not rostime.is_wallclock()
    assert rostime.get_rostime() == Time(100)
    rostime._set_rostime(Time(101, 5))
    assert Time.now() == Time(101, 5)
    assert rostime.get_time() == pytest.approx(101.000000005)
    with pytest.raises(ValueError):
        rostime._set_rostime(123)


def test_sim_sleep_wakes_exactly_when_clock_reaches_target(clock):
    t, result = in_thread(lambda: (rostime.sleep(1.0), Time.now())[1])
    wait_for_waiter()
    rostime._set_rostime(Time(100, 500000000))
    assert t.is_alive()
    rostime._set_rostime(Time(101))
    t.join(5)
    assert not t.is_alive() and "error" not in result
    assert result["value"] == Time(101)


def test_sim_sleep_accepts_duration_and_negative_returns_at_once(clock):
    rostime.sleep(Duration(-1))  # negative: no wait at all, clock never moves
    rostime.sleep(-0.5)
    t, result = in_thread(lambda: rostime.sleep(Duration(0, 1000)))
    wait_for_waiter()
    rostime._set_rostime(Time(100, 1000))
    t.join(5)
    assert not t.is_alive() and result == {"value": None}


def test_sim_sleep_raises_when_time_moves_backwards(clock):
    t, result = in_thread(lambda: rostime.sleep(5))
    wait_for_waiter()
    rostime._set_rostime(Time(98))
    t.join(5)
    assert isinstance(result.get("error"), ROSTimeMovedBackwardsException)
    assert result["error"].time == pytest.approx(2.0)


def test_sim_sleep_waits_for_first_clock_message_when_at_zero(clock):
    rostime._set_rostime(Time(0))
    assert Time.now().is_zero()
    t, result = in_thread(lambda: (rostime.sleep(1), Time.now())[1])
    wait_for_waiter()
    rostime._set_rostime(Time(50))  # first tick: the sleep starts counting from here
    wait_for_waiter()
    assert t.is_alive()
    rostime._set_rostime(Time(51))
    t.join(5)
    assert result["value"] == Time(51)


def test_sleep_raises_interrupt_on_shutdown(clock, monkeypatch):
    monkeypatch.setattr(rostime, "_node_is_shutdown", lambda: True)
    with pytest.raises(ROSInterruptException, match="ROS shutdown request"):
        rostime.sleep(10)


def test_wall_sleep_returns_when_node_shuts_down_and_raises_after(wallclock, monkeypatch):
    """rospy's wall sleep raises nothing, so `while not rospy.is_shutdown(): rate.sleep()`
    ends without a traceback on Ctrl-C; minros's returns early, and the second sleep a thread
    begins after the shutdown raises, so a loop that never looks at is_shutdown() ends."""
    from minros import node

    shut, waiting = threading.Event(), threading.Event()

    def wait_for_shutdown(timeout):
        waiting.set()
        return shut.wait(timeout)

    monkeypatch.setattr(node, "wait_for_shutdown", wait_for_shutdown)
    monkeypatch.setattr(rostime, "_node_is_shutdown", shut.is_set)
    t, result = in_thread(lambda: rostime.sleep(60))
    assert waiting.wait(5)
    shut.set()
    t.join(5)
    assert not t.is_alive()
    assert "error" not in result
    # after the shutdown: the first sleep of a thread sleeps and returns, as rospy's (the
    # Ctrl-C landed between a loop's is_shutdown() and its sleep); a second one raises
    t, result = in_thread(lambda: (rostime.sleep(0.2), rostime.Rate(10).sleep()))
    t.join(5)
    assert not t.is_alive() and isinstance(result.get("error"), ROSInterruptException)
    t, result = in_thread(lambda: (time.monotonic(), rostime.sleep(0.2), time.monotonic()))
    t.join(5)
    assert "error" not in result and result["value"][2] - result["value"][0] >= 0.2


def test_wall_sleep_duration(wallclock):
    start = time.monotonic()
    rostime.sleep(0.05)
    rostime.sleep(Duration(0, 20_000_000))
    assert time.monotonic() - start >= 0.069


# ---------------------------------------------------------------------------- Rate

def test_rate_remaining_and_cycle_accounting(clock):
    rate = Rate(10)  # 0.1 s cycles starting at t=100
    assert rate.sleep_dur == Duration(0, 100000000)
    rostime._set_rostime(Time(100, 30000000))
    assert rate.remaining() == Duration(0, 70000000)
    # already past the end of the cycle: returns at once and the next cycle starts at 100.1
    rostime._set_rostime(Time(100, 150000000))
    rate.sleep()
    assert rate.last_time == Time(100, 100000000)
    assert rate.remaining() == Duration(0, 50000000)
    # more than two cycles behind: the cycle restarts from the current time (no burst)
    rostime._set_rostime(Time(100, 550000000))
    rate.sleep()
    assert rate.last_time == Time(100, 550000000)


def test_rate_sleep_blocks_until_cycle_end(clock):
    rate = Rate(4)  # 0.25 s
    t, result = in_thread(lambda: (rate.sleep(), Time.now())[1])
    wait_for_waiter()
    rostime._set_rostime(Time(100, 200000000))
    assert t.is_alive()
    rostime._set_rostime(Time(100, 250000000))
    t.join(5)
    assert result["value"] == Time(100, 250000000)
    assert rate.last_time == Time(100, 250000000)


def test_rate_time_backwards_raises_unless_reset(clock):
    rate = Rate(1)
    t, result = in_thread(rate.sleep)
    wait_for_waiter()
    rostime._set_rostime(Time(90))
    t.join(5)
    assert isinstance(result.get("error"), ROSTimeMovedBackwardsException)

    rostime._set_rostime(Time(100))
    rate = Rate(1, reset=True)
    t, result = in_thread(rate.sleep)
    wait_for_waiter()
    rostime._set_rostime(Time(90))
    t.join(5)
    assert result == {"value": None}
    assert rate.last_time == Time(90)  # restarted from the new time


def test_rate_on_wall_clock_paces_the_loop(wallclock):
    rate = Rate(100)
    start = time.monotonic()
    for _ in range(5):
        rate.sleep()
    elapsed = time.monotonic() - start
    assert 0.04 <= elapsed < 2.0


# ---------------------------------------------------------------------------- Timer

def test_timer_event_fields_and_periodic_calls(clock):
    events: list = []
    fired = threading.Semaphore(0)

    def callback(event):
        events.append(event)
        fired.release()

    timer = Timer(Duration(0, 100000000), callback)
    try:
        wait_for_waiter()
        rostime._set_rostime(Time(100, 100000000))
        assert fired.acquire(timeout=5)
        first = events[0]
        assert isinstance(first, TimerEvent)
        assert first.last_expected is None and first.last_real is None and first.last_duration is None
        assert first.current_expected == Time(100, 100000000)
        assert first.current_real == Time(100, 100000000)

        wait_for_waiter()
        rostime._set_rostime(Time(100, 230000000))  # late: real differs from expected
        assert fired.acquire(timeout=5)
        second = events[1]
        assert second.last_expected == Time(100, 100000000)
        assert second.last_real == Time(100, 100000000)
        assert second.current_expected == Time(100, 200000000)
        assert second.current_real == Time(100, 230000000)
        assert isinstance(second.last_duration, float) and second.last_duration >= 0
    finally:
        timer.shutdown()
        timer.join(5)
    assert not timer.is_alive()


def test_timer_shutdown_stops_callbacks(clock):
    calls: list = []
    timer = Timer(Duration(1), calls.append)
    wait_for_waiter()
    timer.shutdown()
    timer.join(5)
    assert not timer.is_alive()  # woke up for the shutdown without time moving
    rostime._set_rostime(Time(105))
    assert calls == []


def test_oneshot_timer_fires_once(clock):
    calls: list = []
    timer = Timer(Duration(1), calls.append, oneshot=True)
    wait_for_waiter()
    rostime._set_rostime(Time(101))
    timer.join(5)
    assert not timer.is_alive()
    assert len(calls) == 1 and calls[0].current_expected == Time(101)


def test_timer_on_wall_clock(wallclock):
    fired = threading.Event()
    got: list = []

    def callback(event):
        got.append(event)
        fired.set()

    start = time.time()
    timer = Timer(Duration(0, 20000000), callback, oneshot=True)
    assert fired.wait(5)
    timer.join(5)
    assert got[0].current_real.to_sec() >= start + 0.019
    assert abs(got[0].current_real.to_sec() - got[0].current_expected.to_sec()) < 1.0
