"""Bond: one side of a bond, on a topic of bond/Status heartbeats."""

from __future__ import annotations

import threading
import time
import uuid
from typing import Any, Callable, List, Optional

import minros
from bond.msg import Constants, Status
from minros.bondpy import states

__all__ = ["Bond", "Timeout", "as_float_duration", "as_ros_duration"]


def as_float_duration(d: Any) -> Any:
    """Seconds of a Duration; anything else (a number of seconds) as given."""
    return d.to_sec() if isinstance(d, minros.Duration) else d


def as_ros_duration(d: Any) -> Any:
    """A Duration of ``d`` seconds; a Duration as given."""
    return d if isinstance(d, minros.Duration) else minros.Duration.from_sec(d)


def _seconds(value: Any) -> float:
    return value.to_sec() if hasattr(value, "to_sec") else float(value)


class Timeout:
    """A restartable one-shot timer (wall clock) calling ``on_timeout``."""

    def __init__(self, duration: Any, on_timeout: Optional[Callable[[], None]] = None) -> None:
        self.duration = _seconds(duration)
        self.on_timeout = on_timeout
        self.timer: Optional[threading.Timer] = None
        self.deadline = time.time()

    def reset(self) -> Timeout:
        self.cancel()
        self.timer = threading.Timer(self.duration, self._fire)
        self.timer.daemon = True
        self.timer.start()
        self.deadline = time.time() + self.duration
        return self

    def cancel(self) -> None:
        if self.timer is not None:
            self.timer.cancel()
            self.timer = None

    def left(self) -> Any:
        return minros.Duration(max(0.0, self.deadline - time.time()))

    def _fire(self) -> None:
        if self.on_timeout is not None:
            self.on_timeout()


class Bond:
    """One end of the bond ``(topic, id)``; ``on_formed`` and ``on_broken`` are called
    (outside the bond's lock) when the other end appears and when the bond breaks."""

    def __init__(self, topic: str, id: str, on_broken: Optional[Callable[[], None]] = None,  # noqa: A002
                 on_formed: Optional[Callable[[], None]] = None) -> None:
        self._started = False
        self.topic = topic
        self.id = id
        self.instance_id = str(uuid.uuid4())
        self.sister_instance_id: Optional[str] = None
        self.on_broken = on_broken
        self.on_formed = on_formed
        self.is_shutdown = False
        self.sister_died_first = False
        self.deadline: Optional[Timeout] = None
        self.pending_callbacks: List[Callable[[], None]] = []
        self.state = states.WAITING
        self.lock = threading.RLock()
        self.condition = threading.Condition(self.lock)
        self.connect_timeout = Constants.DEFAULT_CONNECT_TIMEOUT
        self.heartbeat_timeout = Constants.DEFAULT_HEARTBEAT_TIMEOUT
        self.disconnect_timeout = Constants.DEFAULT_DISCONNECT_TIMEOUT
        self.heartbeat_period = Constants.DEFAULT_HEARTBEAT_PERIOD
        self.sub: Any = None
        self.pub = minros.Publisher(self.topic, Status, queue_size=1)

    # timeouts (settable until start(), as in ROS)
    def _check_not_started(self, what: str) -> None:
        if self._started:
            raise RuntimeError(f"set {what} before Bond.start()")

    @property
    def connect_timeout(self) -> float:
        return self._connect_timeout

    @connect_timeout.setter
    def connect_timeout(self, value: Any) -> None:
        self._check_not_started("connect_timeout")
        self._connect_timeout = _seconds(value)
        self.connect_timer = Timeout(self._connect_timeout, self._on_connect_timeout)

    @property
    def heartbeat_timeout(self) -> float:
        return self._heartbeat_timeout

    @heartbeat_timeout.setter
    def heartbeat_timeout(self, value: Any) -> None:
        self._check_not_started("heartbeat_timeout")
        self._heartbeat_timeout = _seconds(value)
        self.heartbeat_timer = Timeout(self._heartbeat_timeout, self._on_heartbeat_timeout)

    @property
    def disconnect_timeout(self) -> float:
        return self._disconnect_timeout

    @disconnect_timeout.setter
    def disconnect_timeout(self, value: Any) -> None:
        self._check_not_started("disconnect_timeout")
        self._disconnect_timeout = _seconds(value)
        self.disconnect_timer = Timeout(self._disconnect_timeout, self._on_disconnect_timeout)

    @property
    def heartbeat_period(self) -> float:
        return self._heartbeat_period

    @heartbeat_period.setter
    def heartbeat_period(self, value: Any) -> None:
        self._check_not_started("heartbeat_period")
        self._heartbeat_period = _seconds(value)

    # the state machine
    def _event(self, event: str) -> None:
        """Take ``event`` (lock held): change state, run the actions."""
        self.state, actions = states.step(self.state, event)
        for action in actions:
            getattr(self, action)()

    def start(self) -> None:
        """Start the heartbeats and listen for the other end."""
        with self.lock:
            self.connect_timer.reset()
            self.sub = minros.Subscriber(self.topic, Status, self._on_bond_status)
            self.thread = threading.Thread(target=self._publishing_thread,
                                           name=f"bond:{self.topic}:{self.id}", daemon=True)
            self.thread.start()
            self._started = True

    def _on_connect_timeout(self) -> None:
        with self.lock:
            self._event("ConnectTimeout")
        self._flush_pending_callbacks()

    def _on_heartbeat_timeout(self) -> None:
        if minros.get_param(Constants.DISABLE_HEARTBEAT_TIMEOUT_PARAM, False):
            minros.logwarn(f"Heartbeat timeout is disabled.  Not breaking bond (topic: "
                           f"{self.topic}, id: {self.id})")
            return
        with self.lock:
            self._event("HeartbeatTimeout")
        self._flush_pending_callbacks()

    def _on_disconnect_timeout(self) -> None:
        with self.lock:
            self._event("DisconnectTimeout")
        self._flush_pending_callbacks()

    def shutdown(self) -> None:
        """Break the bond (if still formed) and close its topic."""
        if self.is_shutdown:
            return
        if self.sub is not None:
            self.sub.unregister()
        with self.lock:
            self.is_shutdown = True
            if self.state != states.DEAD:
                self.break_bond()
            self.pub.unregister()
            self.condition.notify_all()
            self.connect_timer.cancel()
            self.heartbeat_timer.cancel()
            self.disconnect_timer.cancel()
            if self.deadline is not None:
                self.deadline.cancel()

    def _on_bond_status(self, msg: Any) -> None:
        if msg.id != self.id or msg.instance_id == self.instance_id:
            return
        with self.lock:
            if not self.sister_instance_id:
                self.sister_instance_id = msg.instance_id
            if msg.instance_id != self.sister_instance_id:
                minros.logerr(f"More than two locations are trying to use a single bond (topic: "
                              f"{self.topic}, id: {self.id}).  You should only instantiate at "
                              "most two bond instances for each (topic, id) pair.")
                return
            if msg.active:
                self._event("SisterAlive")
            else:
                self._event("SisterDead")
                if self.sister_died_first:
                    self._publish(False)  # answer the sister's death so it stops waiting
        self._flush_pending_callbacks()

    def _publish(self, active: bool) -> None:
        msg = Status(id=self.id, instance_id=self.instance_id, active=active,
                     heartbeat_timeout=self.heartbeat_timeout,
                     heartbeat_period=self.heartbeat_period)
        msg.header.stamp = minros.Time.now()
        self.pub.publish(msg)

    def _publishing_thread(self) -> None:
        with self.lock:
            while not self.is_shutdown and self.state in (states.WAITING, states.ALIVE):
                self._publish(True)
                self.condition.wait(self.heartbeat_period)
            while not self.is_shutdown and self.state == states.AWAIT_SISTER_DEATH:
                self._publish(False)
                self.condition.wait(Constants.DEAD_PUBLISH_PERIOD)

    def _flush_pending_callbacks(self) -> None:
        with self.lock:
            callbacks, self.pending_callbacks = self.pending_callbacks, []
        for callback in callbacks:
            callback()

    # actions of the state machine (names from ROS's BondSM)
    def Connected(self) -> None:
        self.connect_timer.cancel()
        # ROS's bond starts the heartbeat timer only at the second heartbeat, so a sister
        # that dies after its first one is never noticed; start it at the first
        self.heartbeat_timer.reset()
        self.condition.notify_all()
        if self.on_formed:
            self.pending_callbacks.append(self.on_formed)

    def Heartbeat(self) -> None:
        self.heartbeat_timer.reset()

    def SisterDied(self) -> None:
        self.sister_died_first = True

    def Death(self) -> None:
        self.condition.notify_all()
        self.heartbeat_timer.cancel()
        self.disconnect_timer.cancel()
        if self.on_broken:
            self.pending_callbacks.append(self.on_broken)

    def StartDying(self) -> None:
        self.heartbeat_timer.cancel()
        self.disconnect_timer.reset()

    # the API
    def set_formed_callback(self, on_formed: Callable[[], None]) -> None:
        with self.lock:
            self.on_formed = on_formed

    def set_broken_callback(self, on_broken: Callable[[], None]) -> None:
        with self.lock:
            self.on_broken = on_broken

    def _wait(self, done: Callable[[], bool], timeout: Any) -> bool:
        deadline = None if not timeout else time.monotonic() + _seconds(timeout)
        with self.lock:
            while not done():
                if minros.is_shutdown() or self.is_shutdown:
                    break
                left = 0.1 if deadline is None else min(0.1, deadline - time.monotonic())
                if left <= 0:
                    break
                self.condition.wait(left)
            return done()

    def wait_until_formed(self, timeout: Any = None) -> bool:
        """Wait for the other end (True once it was seen)."""
        return self._wait(lambda: self.state != states.WAITING, timeout)

    def wait_until_broken(self, timeout: Any = None) -> bool:
        return self._wait(lambda: self.state == states.DEAD, timeout)

    def is_broken(self) -> bool:
        with self.lock:
            return self.state == states.DEAD

    def break_bond(self) -> None:
        """End the bond from this side; the other end's on_broken runs."""
        with self.lock:
            self._event("Die")
            self._publish(False)
        self._flush_pending_callbacks()

    def __repr__(self) -> str:
        return f"[Bond {self.id}, Instance {self.instance_id} ({self.state})]"
