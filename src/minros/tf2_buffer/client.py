"""BufferClient: tf2_ros's BufferInterface over a buffer server's LookupTransform action."""

from __future__ import annotations

from typing import Any

import minros
from actionlib_msgs.msg import GoalStatus
from minros.actionlib import SimpleActionClient
from minros.tf.buffer import BufferInterface
from minros.tf.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)
from tf2_msgs.msg import LookupTransformAction, LookupTransformGoal, TF2Error

__all__ = ["BufferClient"]

_EXCEPTIONS = {TF2Error.LOOKUP_ERROR: LookupException,
               TF2Error.CONNECTIVITY_ERROR: ConnectivityException,
               TF2Error.EXTRAPOLATION_ERROR: ExtrapolationException,
               TF2Error.INVALID_ARGUMENT_ERROR: InvalidArgumentException,
               TF2Error.TIMEOUT_ERROR: TimeoutException}


def _duration(value: Any) -> Any:
    if value is None:
        return minros.Duration(0)
    return value if hasattr(value, "to_sec") else minros.Duration.from_sec(float(value))


class BufferClient(BufferInterface):
    """Lookups answered by the buffer server at ``ns`` (e.g. ``tf2_buffer_server``)."""

    def __init__(self, ns: str, check_frequency: Any = None,
                 timeout_padding: Any = None) -> None:
        super().__init__()
        self.client = SimpleActionClient(ns, LookupTransformAction)
        self.timeout_padding = _duration(2.0 if timeout_padding is None else timeout_padding)
        if check_frequency is not None:
            minros.logwarn("Argument check_frequency is deprecated and should not be used.")

    def wait_for_server(self, timeout: Any = None) -> bool:
        return self.client.wait_for_server(_duration(timeout))

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any,
                         timeout: Any = None) -> Any:
        goal = LookupTransformGoal(target_frame=target_frame, source_frame=source_frame,
                                   source_time=time, timeout=_duration(timeout), advanced=False)
        return self._process_goal(goal)

    def lookup_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                              source_time: Any, fixed_frame: str, timeout: Any = None) -> Any:
        goal = LookupTransformGoal(target_frame=target_frame, source_frame=source_frame,
                                   source_time=source_time, timeout=_duration(timeout),
                                   target_time=target_time, fixed_frame=fixed_frame,
                                   advanced=True)
        return self._process_goal(goal)

    def can_transform(self, target_frame: str, source_frame: str, time: Any,
                      timeout: Any = None) -> bool:
        try:
            self.lookup_transform(target_frame, source_frame, time, timeout)
            return True
        except TransformException:
            return False

    def can_transform_full(self, target_frame: str, target_time: Any, source_frame: str,
                           source_time: Any, fixed_frame: str, timeout: Any = None) -> bool:
        try:
            self.lookup_transform_full(target_frame, target_time, source_frame, source_time,
                                       fixed_frame, timeout)
            return True
        except TransformException:
            return False

    def _process_goal(self, goal: Any) -> Any:
        self.client.send_goal(goal)
        if not self.client.wait_for_result(goal.timeout + self.timeout_padding):
            self.client.cancel_goal()
            raise TimeoutException("The LookupTransform goal sent to the BufferServer did not "
                                   "come back in the specified time. Something is likely wrong "
                                   "with the server")
        if self.client.get_state() != GoalStatus.SUCCEEDED:
            raise TimeoutException("The LookupTransform goal sent to the BufferServer did not "
                                   "come back with SUCCEEDED status. Something is likely wrong "
                                   "with the server.")
        result = self.client.get_result()
        if result is None:
            raise TransformException("The BufferServer returned None for result!  Something is "
                                     "likely wrong with the server.")
        if result.error.error != TF2Error.NO_ERROR:
            raise _EXCEPTIONS.get(result.error.error, TransformException)(result.error.error_string)
        return result.transform
