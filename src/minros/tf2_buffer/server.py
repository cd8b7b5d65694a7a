"""BufferServer: LookupTransform goals answered from a tf2 Buffer, each as soon as its
transform is available or its timeout passes (then with the lookup's own error)."""

from __future__ import annotations

import threading
import time
from typing import Any, List, Tuple

import minros
from minros.actionlib import ActionServer
from minros.tf.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)
from tf2_msgs.msg import LookupTransformAction, LookupTransformResult, TF2Error

__all__ = ["BufferServer", "error_of"]

_ERRORS = ((LookupException, TF2Error.LOOKUP_ERROR),
           (ConnectivityException, TF2Error.CONNECTIVITY_ERROR),
           (ExtrapolationException, TF2Error.EXTRAPOLATION_ERROR),
           (InvalidArgumentException, TF2Error.INVALID_ARGUMENT_ERROR),
           (TimeoutException, TF2Error.TIMEOUT_ERROR))


def error_of(exc: TransformException) -> Any:
    """The TF2Error a lookup's exception is sent as."""
    for cls, code in _ERRORS:
        if isinstance(exc, cls):
            return TF2Error(error=code, error_string=str(exc))
    return TF2Error(error=TF2Error.TRANSFORM_ERROR, error_string=str(exc))


class BufferServer:
    """Serve ``buffer`` on the action ``ns`` (tf2_ros's default: ``tf2_buffer_server``),
    checking waiting goals every ``check_period`` seconds."""

    def __init__(self, buffer: Any, ns: str = "tf2_buffer_server", check_period: Any = 0.01,
                 auto_start: bool = True) -> None:
        self.buffer = buffer
        self.check_period = check_period.to_sec() if hasattr(check_period, "to_sec") \
            else float(check_period)
        self.lock = threading.Lock()
        self.active: List[Tuple[Any, float]] = []  # (goal handle, deadline on the monotonic clock)
        self._stop = threading.Event()
        self.server = ActionServer(ns, LookupTransformAction, self.goal_cb, self.cancel_cb,
                                   auto_start=False)
        self.thread = threading.Thread(target=self._check_loop, name=f"tf2-buffer-server:{ns}",
                                       daemon=True)
        if auto_start:
            self.start()

    def start(self) -> None:
        self.server.start()
        self.thread.start()

    def stop(self) -> None:
        self._stop.set()

    def _available(self, goal: Any) -> bool:
        if goal.advanced:
            return bool(self.buffer.can_transform_full(goal.target_frame, goal.target_time,
                                                       goal.source_frame, goal.source_time,
                                                       goal.fixed_frame))
        return bool(self.buffer.can_transform(goal.target_frame, goal.source_frame,
                                              goal.source_time))

    def _result(self, goal: Any) -> Any:
        result = LookupTransformResult()
        try:
            if goal.advanced:
                result.transform = self.buffer.lookup_transform_full(
                    goal.target_frame, goal.target_time, goal.source_frame, goal.source_time,
                    goal.fixed_frame)
            else:
                result.transform = self.buffer.lookup_transform(goal.target_frame,
                                                                goal.source_frame,
                                                                goal.source_time)
        except TransformException as exc:
            result.error = error_of(exc)
        return result

    def goal_cb(self, gh: Any) -> None:
        goal = gh.get_goal()
        gh.set_accepted()
        timeout = goal.timeout.to_sec()
        if timeout <= 0 or self._available(goal):
            gh.set_succeeded(self._result(goal))
            return
        with self.lock:
            self.active.append((gh, time.monotonic() + timeout))

    def cancel_cb(self, gh: Any) -> None:
        with self.lock:
            for i, (active, _) in enumerate(self.active):
                if active == gh:
                    del self.active[i]
                    gh.set_canceled()
                    return

    def _check_loop(self) -> None:
        while not self._stop.wait(self.check_period) and not minros.is_shutdown():
            now = time.monotonic()
            with self.lock:
                ready = [(gh, end) for gh, end in self.active
                         if end < now or self._available(gh.get_goal())]
                self.active = [entry for entry in self.active if entry not in ready]
            for gh, _ in ready:
                gh.set_succeeded(self._result(gh.get_goal()))
