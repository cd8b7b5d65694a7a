"""SimpleActionClient: one goal at a time, with done/active/feedback callbacks."""

from __future__ import annotations

import threading
from typing import Any, Callable

import minros
from actionlib_msgs.msg import GoalStatus

from .client import ActionClient, ClientGoalHandle, _duration
from .states import CommState, SimpleGoalState


class SimpleActionClient:
    """A client that tracks only the goal it sent last."""

    def __init__(self, ns: str, ActionSpec: type) -> None:
        self.action_client = ActionClient(ns, ActionSpec)
        self.simple_state = SimpleGoalState.DONE
        self.gh: ClientGoalHandle | None = None
        self.done_condition = threading.Condition()
        # Held while a goal is sent and while its callbacks run: a fast server's first status
        # can arrive before send_goal has stored the handle, and must wait for it rather than
        # be dropped as "not tracking" (ROS 1's client then never calls active_cb).
        self._tracking = threading.RLock()
        self.done_cb: Callable | None = None
        self.active_cb: Callable | None = None
        self.feedback_cb: Callable | None = None

    def wait_for_server(self, timeout: Any = None) -> bool:
        """Block until the server is connected (a zero timeout waits forever)."""
        return self.action_client.wait_for_server(timeout)

    def send_goal(self, goal: Any, done_cb: Callable | None = None, active_cb: Callable | None = None,
                  feedback_cb: Callable | None = None) -> None:
        """Send ``goal`` and forget the previous one (without cancelling it)."""
        with self._tracking:
            self.stop_tracking_goal()
            self.done_cb = done_cb
            self.active_cb = active_cb
            self.feedback_cb = feedback_cb
            self.simple_state = SimpleGoalState.PENDING
            self.gh = self.action_client.send_goal(goal, self._handle_transition,
                                                   self._handle_feedback)

    def send_goal_and_wait(self, goal: Any, execute_timeout: Any = None,
                           preempt_timeout: Any = None) -> int:
        """Send ``goal``, wait for it, cancel it after ``execute_timeout``; return its state."""
        self.send_goal(goal)
        if not self.wait_for_result(execute_timeout):
            minros.logdebug("Canceling goal")
            self.cancel_goal()
            preempt_timeout = _duration(preempt_timeout)
            if self.wait_for_result(preempt_timeout):
                minros.logdebug("Preempt finished within specified preempt_timeout [%.2f]",
                                preempt_timeout.to_sec())
            else:
                minros.logdebug("Preempt didn't finish specified preempt_timeout [%.2f]",
                                preempt_timeout.to_sec())
        return self.get_state()

    def wait_for_result(self, timeout: Any = None) -> bool:
        """Block until the goal is done (a zero timeout waits forever); whether it is."""
        if not self.gh:
            minros.logerr("Called wait_for_result when no goal exists")
            return False
        timeout = _duration(timeout)
        forever = timeout == minros.Duration(0)
        deadline = minros.get_rostime() + timeout
        # woken by the DONE transition; the 0.1 s cap notices shutdown and simulated time
        period = minros.Duration(0.1)
        with self.done_condition:
            while not minros.is_shutdown() and self.simple_state != SimpleGoalState.DONE:
                left = deadline - minros.get_rostime()
                if not forever and left <= minros.Duration(0):
                    break
                self.done_condition.wait((period if forever or left > period else left).to_sec())
        return self.simple_state == SimpleGoalState.DONE

    def get_result(self) -> Any:
        if not self.gh:
            minros.logerr("Called get_result when no goal is running")
            return None
        return self.gh.get_result()

    def get_state(self) -> int:
        """The goal's status; RECALLING reads as PENDING, PREEMPTING as ACTIVE, no goal as LOST."""
        if not self.gh:
            return GoalStatus.LOST
        status = self.gh.get_goal_status()
        if status == GoalStatus.RECALLING:
            return GoalStatus.PENDING
        if status == GoalStatus.PREEMPTING:
            return GoalStatus.ACTIVE
        return status

    def get_goal_status_text(self) -> str:
        if not self.gh:
            minros.logerr("Called get_goal_status_text when no goal is running")
            return "ERROR: Called get_goal_status_text when no goal is running"
        return self.gh.get_goal_status_text()

    def cancel_all_goals(self) -> None:
        self.action_client.cancel_all_goals()

    def cancel_goals_at_and_before_time(self, time: Any) -> None:
        self.action_client.cancel_goals_at_and_before_time(time)

    def cancel_goal(self) -> None:
        if self.gh:
            self.gh.cancel()

    def stop_tracking_goal(self) -> None:
        self.gh = None

    def _handle_transition(self, gh: ClientGoalHandle) -> None:
        with self._tracking:
            self._transition(gh)

    def _transition(self, gh: ClientGoalHandle) -> None:
        if gh != self.gh:
            minros.logerr("Got a transition callback on a goal handle that we're not tracking")
            return
        comm_state = gh.get_comm_state()
        simple = self.simple_state
        if comm_state in (CommState.ACTIVE, CommState.PREEMPTING):
            if simple == SimpleGoalState.PENDING:
                self._set_simple_state(SimpleGoalState.ACTIVE)
                if self.active_cb:
                    self.active_cb()
            elif simple == SimpleGoalState.DONE:
                self._log_unexpected(comm_state)
        elif comm_state == CommState.RECALLING:
            if simple != SimpleGoalState.PENDING:
                self._log_unexpected(comm_state)
        elif comm_state == CommState.DONE:
            if simple in (SimpleGoalState.PENDING, SimpleGoalState.ACTIVE):
                if self.done_cb:
                    self.done_cb(gh.get_goal_status(), gh.get_result())
                with self.done_condition:
                    self._set_simple_state(SimpleGoalState.DONE)
                    self.done_condition.notify_all()
            else:
                minros.logerr("SimpleActionClient received DONE twice")

    def _log_unexpected(self, comm_state: int) -> None:
        minros.logerr(f"Received comm state {CommState.to_string(comm_state)} when in simple state "
                      f"{SimpleGoalState.to_string(self.simple_state)} with SimpleActionClient in "
                      f"NS {minros.resolve_name(self.action_client.ns)}")

    def _handle_feedback(self, gh: ClientGoalHandle, feedback: Any) -> None:
        with self._tracking:
            self._feedback(gh, feedback)

    def _feedback(self, gh: ClientGoalHandle, feedback: Any) -> None:
        if not self.gh:
            return  # feedback of a goal we stopped tracking, still in flight
        if gh != self.gh:
            minros.logerr("Got a feedback callback on a goal handle that we're not tracking. "
                          f"{self.gh.comm_state_machine.goal_id} vs {gh.comm_state_machine.goal_id}")
            return
        if self.feedback_cb:
            self.feedback_cb(feedback)

    def _set_simple_state(self, state: int) -> None:
        self.simple_state = state
