"""SimpleActionServer: one active goal at a time, newer goals preempt older ones.

Two ways to use it: an execute callback, run in a thread of its own for each accepted goal
(it must end the goal with set_succeeded/set_aborted/set_preempted), or goal and preempt
callbacks with :meth:`SimpleActionServer.accept_new_goal` called by the user.
"""

from __future__ import annotations

import threading
import traceback
from typing import Any, Callable

import minros
from actionlib_msgs.msg import GoalStatus

from .server import ActionServer, ServerGoalHandle

_BUMPED = "This goal was canceled because another goal was received by the simple action server"


class SimpleActionServer:
    """Single-goal policy on top of :class:`ActionServer`."""

    def __init__(self, name: str, ActionSpec: type, execute_cb: Callable | None = None,
                 auto_start: bool = True) -> None:
        self.new_goal = False
        self.preempt_request = False
        self.new_goal_preempt_request = False
        self.execute_callback = execute_cb
        self.goal_callback: Callable | None = None
        self.preempt_callback: Callable | None = None
        self.need_to_terminate = False
        self.terminate_mutex = threading.RLock()
        # Lock order: the ActionServer's lock first, then this one (the ActionServer calls our
        # callbacks while holding its lock).
        self.lock = threading.RLock()
        self.execute_condition = threading.Condition(self.lock)
        self.current_goal = ServerGoalHandle()
        self.next_goal = ServerGoalHandle()
        self.execute_thread: threading.Thread | None = None
        if execute_cb:
            self.execute_thread = threading.Thread(target=self.executeLoop, daemon=True,
                                                   name=f"actionlib-execute:{name}")
            self.execute_thread.start()
        self.action_server = ActionServer(name, ActionSpec, self.internal_goal_callback,
                                          self.internal_preempt_callback, auto_start)

    def accept_new_goal(self) -> Any:
        """Make the waiting goal the current one (preempting the old); return its goal."""
        with self.action_server.lock, self.lock:
            if not self.new_goal or not self.next_goal.get_goal():
                minros.logerr("Attempting to accept the next goal when a new goal is not available")
                return None
            if self.is_active() and self.current_goal.get_goal() and self.current_goal != self.next_goal:
                self.current_goal.set_canceled(None, _BUMPED)
            minros.logdebug("Accepting a new goal")
            self.current_goal = self.next_goal
            self.new_goal = False
            self.preempt_request = self.new_goal_preempt_request
            self.new_goal_preempt_request = False
            self.current_goal.set_accepted("This goal has been accepted by the simple action server")
            return self.current_goal.get_goal()

    def is_new_goal_available(self) -> bool:
        return self.new_goal

    def is_preempt_requested(self) -> bool:
        return self.preempt_request

    def is_active(self) -> bool:
        if not self.current_goal.get_goal():
            return False
        status = self.current_goal.get_goal_status().status
        return status in (GoalStatus.ACTIVE, GoalStatus.PREEMPTING)

    def set_succeeded(self, result: Any = None, text: str = "") -> None:
        with self.action_server.lock, self.lock:
            self.current_goal.set_succeeded(result or self.get_default_result(), text)

    def set_aborted(self, result: Any = None, text: str = "") -> None:
        with self.action_server.lock, self.lock:
            self.current_goal.set_aborted(result or self.get_default_result(), text)

    def set_preempted(self, result: Any = None, text: str = "") -> None:
        with self.action_server.lock, self.lock:
            minros.logdebug("Setting the current goal as canceled")
            self.current_goal.set_canceled(result or self.get_default_result(), text)

    def publish_feedback(self, feedback: Any) -> None:
        self.current_goal.publish_feedback(feedback)

    def get_default_result(self) -> Any:
        return self.action_server.ActionResultType()

    def register_goal_callback(self, cb: Callable) -> None:
        if self.execute_callback:
            minros.logwarn("Cannot call SimpleActionServer.register_goal_callback() because an "
                           "executeCallback exists. Not going to register it.")
        else:
            self.goal_callback = cb

    def register_preempt_callback(self, cb: Callable) -> None:
        self.preempt_callback = cb

    def start(self) -> None:
        self.action_server.start()

    def internal_goal_callback(self, goal: ServerGoalHandle) -> None:
        """A goal arrived: it replaces the waiting one if it is at least as new as both the
        current and the waiting goal, else it is canceled right away."""
        with self.execute_condition:
            try:
                minros.logdebug("A new goal %s has been received by the single goal action server",
                                goal.get_goal_id().id)
                stamp = goal.get_goal_id().stamp
                newest = ((not self.current_goal.get_goal()
                           or stamp >= self.current_goal.get_goal_id().stamp)
                          and (not self.next_goal.get_goal()
                               or stamp >= self.next_goal.get_goal_id().stamp))
                if not newest:
                    goal.set_canceled(None, _BUMPED)
                    return
                if self.next_goal.get_goal() and (not self.current_goal.get_goal()
                                                  or self.next_goal != self.current_goal):
                    self.next_goal.set_canceled(None, _BUMPED)  # never started: tell its client
                self.next_goal = goal
                self.new_goal = True
                self.new_goal_preempt_request = False
                if self.is_active():
                    self.preempt_request = True
                    if self.preempt_callback:
                        self.preempt_callback()
                if self.goal_callback:
                    self.goal_callback()
                self.execute_condition.notify()
            except Exception as exc:  # noqa: BLE001 - a user callback must not kill the subscriber
                minros.logerr("SimpleActionServer.internal_goal_callback - exception %s", str(exc))

    def internal_preempt_callback(self, preempt: ServerGoalHandle) -> None:
        with self.lock:
            minros.logdebug("A preempt has been received by the SimpleActionServer")
            if preempt == self.current_goal:
                minros.logdebug("Setting preempt_request bit for the current goal to TRUE and "
                                "invoking callback")
                self.preempt_request = True
                if self.preempt_callback:
                    self.preempt_callback()
            elif preempt == self.next_goal:
                minros.logdebug("Setting preempt request bit for the next goal to TRUE")
                self.new_goal_preempt_request = True

    def executeLoop(self) -> None:
        """The execute thread: wait for a goal, run the user's callback on it, repeat."""
        while not minros.is_shutdown():
            with self.terminate_mutex:
                if self.need_to_terminate:
                    break
            if self.is_active():
                minros.logerr("Should never reach this code with an active goal")
                return
            if self.is_new_goal_available():
                goal = self.accept_new_goal()
                try:
                    self.execute_callback(goal)
                    if self.is_active():
                        minros.logwarn(
                            "Your executeCallback did not set the goal to a terminal status.  "
                            "This is a bug in your ActionServer implementation. Fix your code!  "
                            "For now, the ActionServer will set this goal to aborted")
                        self.set_aborted(None, "No terminal state was set.")
                except Exception as exc:  # noqa: BLE001 - report the user's bug, keep serving
                    minros.logerr("Exception in your execute callback: %s\n%s", str(exc),
                                  traceback.format_exc())
                    self.set_aborted(None, f"Exception in execute callback: {str(exc)}")
            with self.execute_condition:
                if not self.new_goal:
                    # woken by a new goal; the timeout notices shutdown
                    self.execute_condition.wait(0.1)

    def shutdown(self) -> None:
        """Stop the execute thread (after the running callback returns)."""
        with self.terminate_mutex:
            self.need_to_terminate = True
        with self.execute_condition:
            self.execute_condition.notify_all()
