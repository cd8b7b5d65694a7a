"""MonitorState: watch a topic while a condition holds (valid, invalid, preempted)."""

from __future__ import annotations

import threading
from typing import Any, Callable, Sequence

import minros
from minros import smach

__all__ = ["MonitorState"]


class MonitorState(smach.State):
    """Subscribe to ``topic`` while the state runs; each message goes to
    ``cond_cb(ud, msg)``. The first False (or exception) ends with 'invalid'; ``max_checks``
    True answers in a row end with 'valid' (-1: watch until False or preempted)."""

    def __init__(self, topic: str, msg_type: type, cond_cb: Callable[[Any, Any], bool],
                 max_checks: int = -1, input_keys: Sequence[str] = (),
                 output_keys: Sequence[str] = ()) -> None:
        super().__init__(outcomes=["valid", "invalid", "preempted"], input_keys=input_keys,
                         output_keys=output_keys)
        self._topic = topic
        self._msg_type = msg_type
        self._cond_cb = cond_cb
        self._max_checks = max_checks
        self._n_checks = 0
        self._trigger_event = threading.Event()

    def execute(self, ud: Any) -> str:
        if self.preempt_requested():
            self.service_preempt()
            return "preempted"
        self._n_checks = 0
        self._trigger_event.clear()
        sub = minros.Subscriber(self._topic, self._msg_type, self._cb, callback_args=ud)
        try:
            while not self._trigger_event.wait(0.1):
                if minros.is_shutdown():
                    break
        finally:
            sub.unregister()
        if self.preempt_requested():
            self.service_preempt()
            return "preempted"
        if 0 < self._max_checks <= self._n_checks:
            return "valid"
        return "invalid"

    def _cb(self, msg: Any, ud: Any) -> None:
        if self._trigger_event.is_set():
            return  # a message that arrived while the subscription was being closed
        try:
            if self._cond_cb(ud, msg):
                self._n_checks += 1
            else:
                self._trigger_event.set()
        except Exception as e:  # noqa: BLE001 - user code: ends the state with 'invalid'
            minros.logerr(f"Error thrown while executing condition callback {self._cond_cb}: {e}")
            self._trigger_event.set()
        if 0 < self._max_checks <= self._n_checks:
            self._trigger_event.set()

    def request_preempt(self) -> None:
        super().request_preempt()
        self._trigger_event.set()
