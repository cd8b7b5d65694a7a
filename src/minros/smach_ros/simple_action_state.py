"""SimpleActionState: an actionlib goal as a smach state (succeeded, aborted, preempted)."""

from __future__ import annotations

import copy
import threading
import time
import traceback
from typing import Any, Callable, Dict, Optional, Sequence

import minros
from actionlib_msgs.msg import GoalStatus
from minros import smach
from minros.actionlib import SimpleActionClient
from minros.smach_ros._callbacks import callback_interface

__all__ = ["SimpleActionState"]


def _seconds(value: Any) -> Optional[float]:
    if value is None:
        return None
    return value.to_sec() if hasattr(value, "to_sec") else float(value)


class SimpleActionState(smach.State):
    """Send a goal to ``action_name`` and end with the result's status.

    The goal is, in order: ``goal`` (or the action's default goal), replaced by
    ``ud[goal_key]``, fields set from ``goal_slots`` keys, then ``goal_cb(ud, goal)`` (its
    return value, if not None, is the goal sent). On the result, ``result_cb(ud, status,
    result)`` may return an outcome; ``result_key`` and ``result_slots`` store the result.
    ``exec_timeout`` cancels a goal that runs too long; ``server_wait_timeout`` bounds the
    wait for the server, after which the state aborts.
    """

    WAITING_FOR_SERVER = 0
    INACTIVE = 1
    ACTIVE = 2
    PREEMPTING = 3
    COMPLETED = 4

    def __init__(self, action_name: str, action_spec: type, goal: Any = None,
                 goal_key: Optional[str] = None, goal_slots: Sequence[str] = (),
                 goal_cb: Optional[Callable[..., Any]] = None, goal_cb_args: Sequence[Any] = (),
                 goal_cb_kwargs: Optional[Dict[str, Any]] = None,
                 result_key: Optional[str] = None, result_slots: Sequence[str] = (),
                 result_cb: Optional[Callable[..., Any]] = None,
                 result_cb_args: Sequence[Any] = (),
                 result_cb_kwargs: Optional[Dict[str, Any]] = None,
                 input_keys: Sequence[str] = (), output_keys: Sequence[str] = (),
                 outcomes: Sequence[str] = (), exec_timeout: Any = None,
                 preempt_timeout: Any = 60.0, server_wait_timeout: Any = 60.0) -> None:
        super().__init__(outcomes=["succeeded", "aborted", "preempted"])
        self._action_name = action_name
        self._action_spec = action_spec
        self._exec_timeout = _seconds(exec_timeout)
        self._preempt_timeout = _seconds(preempt_timeout)
        self._server_wait_timeout = _seconds(server_wait_timeout)
        spec = action_spec()
        goal_fields = spec.action_goal.goal.__slots__
        result_fields = spec.action_result.result.__slots__
        if goal is not None and callable(goal) and not hasattr(goal, "__slots__"):
            raise smach.InvalidStateError("Goal object given to SimpleActionState that IS a "
                                          "function object")
        if not all(s in goal_fields for s in goal_slots):
            raise smach.InvalidStateError(f"Goal slots specified are not valid slots. Available "
                                          f"slots: {list(goal_fields)}; specified slots: "
                                          f"{list(goal_slots)}")
        if not all(s in result_fields for s in result_slots):
            raise smach.InvalidStateError(f"Result slots specified are not valid slots. "
                                          f"Available slots: {list(result_fields)}; specified "
                                          f"slots: {list(result_slots)}")
        self._goal = copy.copy(spec.action_goal.goal) if goal is None else goal
        self._goal_key = goal_key
        if goal_key is not None:
            self.register_input_keys([goal_key])
        self._goal_slots = list(goal_slots)
        self.register_input_keys(goal_slots)
        self._goal_cb = goal_cb
        self._goal_cb_args = list(goal_cb_args)
        self._goal_cb_kwargs = dict(goal_cb_kwargs or {})
        self._goal_cb_keys = callback_interface(self, goal_cb, "Goal", input_keys, output_keys)
        self._result_cb = result_cb
        self._result_cb_args = list(result_cb_args)
        self._result_cb_kwargs = dict(result_cb_kwargs or {})
        self._result_cb_keys = callback_interface(self, result_cb, "Result", input_keys,
                                                  output_keys, with_outcomes=True)
        self._result_key = result_key
        if result_key is not None:
            self.register_output_keys([result_key])
        self._result_slots = list(result_slots)
        self.register_output_keys(result_slots)
        self.register_input_keys(input_keys)
        self.register_output_keys(output_keys)
        self.register_outcomes(outcomes)

        self._goal_status = 0
        self._goal_result: Any = None
        self._status = SimpleActionState.WAITING_FOR_SERVER
        self._done = threading.Event()
        self._action_client = SimpleActionClient(action_name, action_spec)
        # Wait for the server in the background, so that building a state machine with many
        # action states does not wait for each server in turn.
        self._action_wait_thread = threading.Thread(
            name=f"{action_name}/wait_for_server", target=self._wait_for_server, daemon=True)
        self._action_wait_thread.start()

    def _wait_for_server(self) -> None:
        deadline = time.monotonic() + (self._server_wait_timeout or 0.0)
        while (self._status == SimpleActionState.WAITING_FOR_SERVER
               and not minros.is_shutdown() and time.monotonic() < deadline):
            try:
                if self._action_client.wait_for_server(minros.Duration(1.0)):
                    self._status = SimpleActionState.INACTIVE
            except Exception:  # noqa: BLE001 - shutdown while waiting
                if not minros.is_shutdown():
                    minros.logerr(f"Failed to wait for action server '{self._action_name}'")
                return
            if self.preempt_requested():
                return

    def request_preempt(self) -> None:
        minros.loginfo(f"Preempt requested on action '{self._action_name}'")
        super().request_preempt()
        if self._status == SimpleActionState.ACTIVE:
            minros.loginfo(f"Preempt on action '{self._action_name}' cancelling goal: \n"
                           f"{self._goal}")
            self._action_client.cancel_goal()

    def execute(self, ud: Any) -> Optional[str]:
        if self._status == SimpleActionState.WAITING_FOR_SERVER:
            minros.logwarn(f"Still waiting for action server '{self._action_name}' to start... "
                           "is it running?")
            if self._action_wait_thread.is_alive():
                self._action_wait_thread.join()
            else:
                self._wait_for_server()
            if not self.preempt_requested() and \
                    self._status != SimpleActionState.WAITING_FOR_SERVER:
                minros.loginfo(f"Connected to action server '{self._action_name}'.")
        if self.preempt_requested():
            minros.loginfo(f"Preempting {self._action_name} before sending goal.")
            self.service_preempt()
            return "preempted"
        if self._status == SimpleActionState.WAITING_FOR_SERVER:
            minros.logfatal(f"Action server for {self._action_name} is not running.")
            return "aborted"
        self._status = SimpleActionState.INACTIVE

        if self._goal_key is not None:
            self._goal = ud[self._goal_key]
        for key in self._goal_slots:
            setattr(self._goal, key, ud[key])
        if self._goal_cb is not None:
            try:
                update = self._goal_cb(smach.Remapper(ud, *self._goal_cb_keys, {}), self._goal,
                                       *self._goal_cb_args, **self._goal_cb_kwargs)
            except Exception:  # noqa: BLE001 - user code
                minros.logerr("Could not execute goal callback: " + traceback.format_exc())
                return "aborted"
            if update is not None:
                self._goal = update
        if self._goal is None:
            minros.logerr(f"Attempting to activate action {self._action_name} with no goal or "
                          "goal callback set. Did you construct the SimpleActionState properly?")
            return "aborted"

        self._done.clear()
        self._goal_result = None
        activated = time.monotonic()
        self._status = SimpleActionState.ACTIVE
        self._action_client.send_goal(self._goal, self._goal_done_cb, self._goal_active_cb,
                                      self._goal_feedback_cb)
        cancelled_at: Optional[float] = None
        while not self._done.wait(0.05):
            now = time.monotonic()
            if minros.is_shutdown():
                return "aborted"
            if self._exec_timeout and cancelled_at is None and now - activated > self._exec_timeout:
                minros.logwarn(f"Action {self._action_name} timed out after "
                               f"{self._exec_timeout:g} seconds.")
                self._action_client.cancel_goal()
                cancelled_at = now
            if cancelled_at is None and self.preempt_requested():
                self._action_client.cancel_goal()  # a preempt that came before the goal left
                cancelled_at = now
            if cancelled_at is not None and self._preempt_timeout is not None \
                    and now - cancelled_at > self._preempt_timeout:
                minros.logwarn(f"Action {self._action_name} did not end within "
                               f"{self._preempt_timeout:g} s of its cancel.")
                self._status = SimpleActionState.INACTIVE
                if self.preempt_requested():
                    self.service_preempt()
                    return "preempted"
                return "aborted"

        result_outcome = None
        if self._result_cb is not None:
            try:
                result_outcome = self._result_cb(smach.Remapper(ud, *self._result_cb_keys, {}),
                                                 self._goal_status, self._goal_result,
                                                 *self._result_cb_args, **self._result_cb_kwargs)
            except Exception:  # noqa: BLE001 - user code
                minros.logerr("Could not execute result callback: " + traceback.format_exc())
                return "aborted"
            if result_outcome is not None and result_outcome not in self.get_registered_outcomes():
                minros.logerr(f"Result callback for action {self._action_name}, {self._result_cb} "
                              "was not registered with the result_cb_outcomes argument. The "
                              f"result callback returned '{result_outcome}' but the only "
                              f"registered outcomes are: {self.get_registered_outcomes()}")
                return "aborted"
        if self._result_key is not None:
            ud[self._result_key] = self._goal_result
        if self._goal_result is not None:
            for key in self._result_slots:
                ud[key] = getattr(self._goal_result, key)

        if self._goal_status == GoalStatus.SUCCEEDED:
            outcome = "succeeded"
        elif self._goal_status == GoalStatus.PREEMPTED and self.preempt_requested():
            outcome = "preempted"
            self.service_preempt()
        else:
            outcome = "aborted"
        self._status = SimpleActionState.INACTIVE
        return result_outcome if result_outcome is not None else outcome

    def _goal_active_cb(self) -> None:
        minros.logdebug(f"Action {self._action_name} has gone active.")

    def _goal_feedback_cb(self, feedback: Any) -> None:
        minros.logdebug(f"Action {self._action_name} sent feedback.")

    def _goal_done_cb(self, result_state: int, result: Any) -> None:
        self._goal_status = result_state
        self._goal_result = result
        self._status = SimpleActionState.COMPLETED
        self._done.set()
