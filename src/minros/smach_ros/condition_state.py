"""ConditionState: poll a condition (true, false, preempted)."""

from __future__ import annotations

import time
import traceback
from typing import Any, Callable, Sequence

import minros
from minros import smach

__all__ = ["ConditionState"]


def _seconds(value: Any) -> float:
    return 0.0 if value is None else value.to_sec() if hasattr(value, "to_sec") else float(value)


class ConditionState(smach.State):
    """Call ``cond_cb(ud)`` every ``poll_rate`` seconds: 'true' as soon as it is true,
    'false' after ``max_checks`` checks (-1: no limit) or ``timeout``."""

    def __init__(self, cond_cb: Callable[[Any], bool], input_keys: Sequence[str] = (),
                 poll_rate: Any = 0.05, timeout: Any = None, max_checks: int = 1) -> None:
        super().__init__(outcomes=["true", "false", "preempted"], input_keys=input_keys)
        self._cond_cb = cond_cb
        if smach.has_smach_interface(cond_cb):
            self.register_input_keys(cond_cb.get_registered_input_keys())
            self.register_output_keys(cond_cb.get_registered_output_keys())
        self._poll_rate = poll_rate
        self._timeout = timeout
        self._max_checks = max_checks

    def execute(self, ud: Any) -> str:
        start = time.monotonic()
        timeout = _seconds(self._timeout)
        checks = 0
        while self._max_checks == -1 or checks < self._max_checks:
            if timeout and time.monotonic() - start > timeout:
                break
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
            try:
                if self._cond_cb(ud):
                    return "true"
            except Exception:  # noqa: BLE001 - user code
                raise smach.InvalidUserCodeError(
                    f"Error thrown while executing condition callback {self._cond_cb}: "
                    + traceback.format_exc()) from None
            checks += 1
            minros.sleep(_seconds(self._poll_rate))
        return "false"
