"""The action server: ActionServer, its goal handles and the status list it publishes.

Topics (under the action namespace): the server subscribes to ``goal`` and ``cancel`` and
publishes ``status`` (latched, every 1/``actionlib_status_frequency`` s, default 5 Hz, and on
every change), ``result`` and ``feedback``. Every goal it has heard of has a
:class:`StatusTracker` in the status list; a goal that reached a terminal status leaves the list
``status_list_timeout`` seconds (default 5) later.
"""

from __future__ import annotations

import threading
from typing import Any, Callable, List

import minros
from actionlib_msgs.msg import GoalID, GoalStatus, GoalStatusArray

from .client import action_types
from .states import SERVER_REFUSALS, cancel_matches, server_transition


class GoalIDGenerator:
    """Unique goal ids ``<name>-<count>-<secs>.<nsecs>`` for goals that came without one."""

    #: goal ids generated so far by every generator of the process (actionlib's s_goalcount)
    issued = 0
    _lock = threading.Lock()

    def __init__(self, name: str | None = None) -> None:
        self.name = name if name is not None else minros.get_name()

    def set_name(self, name: str) -> None:
        self.name = name

    def generate_ID(self) -> Any:
        now = minros.Time.now()
        with GoalIDGenerator._lock:
            GoalIDGenerator.issued += 1
            count = GoalIDGenerator.issued
        return GoalID(id=f"{self.name}-{count}-{now.secs}.{now.nsecs}", stamp=now)


class StatusTracker:
    """The status of one goal in the server's list (made from a goal, or from a cancel
    request that arrived before its goal)."""

    def __init__(self, goal_id: Any = None, status: int | None = None, goal: Any = None) -> None:
        self.goal = None
        self.handle_tracker: Any = None
        self.status = GoalStatus()
        #: when the goal may leave the list (zero: not while it is alive)
        self.handle_destruction_time = minros.Time()
        if goal_id:
            self.status.goal_id = goal_id
            self.status.status = status
            return
        self.goal = goal
        self.status.goal_id = goal.goal_id
        self.status.status = GoalStatus.PENDING
        if self.status.goal_id.id == "":
            self.status.goal_id = GoalIDGenerator().generate_ID()
        if self.status.goal_id.stamp == minros.Time():
            self.status.goal_id.stamp = minros.Time.now()


class HandleTrackerDeleter:
    """Starts a goal's removal countdown when its last handle goes (kept for API parity:
    Python handles have no destructor hook, so terminal transitions start it instead)."""

    def __init__(self, action_server: ActionServer, status_tracker: StatusTracker) -> None:
        self.action_server = action_server
        self.status_tracker = status_tracker

    def __call__(self, _ptr: Any = None) -> None:
        if self.action_server:
            with self.action_server.lock:
                self.status_tracker.handle_destruction_time = minros.Time.now()


class ServerGoalHandle:
    """The user's handle on a goal the server received: accept, reject, succeed, ..."""

    def __init__(self, status_tracker: StatusTracker | None = None, action_server: Any = None,
                 handle_tracker: Any = None) -> None:
        self.status_tracker = status_tracker
        self.action_server = action_server
        self.handle_tracker = handle_tracker
        self.goal = status_tracker.goal if status_tracker else None

    def get_default_result(self) -> Any:
        return self.action_server.ActionResultType()

    def _goal_ref(self) -> str:
        goal_id = self.get_goal_id()
        return f"id: {goal_id.id}, stamp: {goal_id.stamp.to_sec():.2f}"

    def _move(self, operation: str, text: str) -> Any:
        """Apply ``operation`` to the goal's status (the caller holds the server's lock): the
        status, or None (after actionlib's error line) when the goal cannot take it."""
        status = self.status_tracker.status
        new = server_transition(operation, status.status)
        if new is None:
            minros.logerr(SERVER_REFUSALS[operation], status.status)
            return None
        status.status = new
        status.text = text
        return status

    def _finish(self, operation: str, result: Any, text: str) -> None:
        """Move the goal to a terminal status and publish its result."""
        if not self.goal:
            minros.logerr("Attempt to set status on an uninitialized ServerGoalHandle")
            return
        if not result:
            result = self.get_default_result()
        with self.action_server.lock:
            status = self._move(operation, text)
            if status is not None:
                self.status_tracker.handle_destruction_time = minros.Time.now()
                self.action_server.publish_result(status, result)

    def set_accepted(self, text: str = "") -> None:
        """PENDING -> ACTIVE, or RECALLING -> PREEMPTING if a cancel came first."""
        minros.logdebug("Accepting goal, %s", self._goal_ref())
        if not self.goal:
            minros.logerr("Attempt to set status on an uninitialized ServerGoalHandle")
            return
        with self.action_server.lock:
            if self._move("accept", text) is not None:
                self.action_server.publish_status()

    def set_canceled(self, result: Any = None, text: str = "") -> None:
        """RECALLED if the goal never ran, PREEMPTED if it was running."""
        minros.logdebug("Setting status to canceled on goal, %s", self._goal_ref())
        self._finish("cancel", result, text)

    def set_rejected(self, result: Any = None, text: str = "") -> None:
        minros.logdebug("Setting status to rejected on goal, %s", self._goal_ref())
        self._finish("reject", result, text)

    def set_aborted(self, result: Any = None, text: str = "") -> None:
        minros.logdebug("Setting status to aborted on goal, %s", self._goal_ref())
        self._finish("abort", result, text)

    def set_succeeded(self, result: Any = None, text: str = "") -> None:
        minros.logdebug("Setting status to succeeded on goal, %s", self._goal_ref())
        self._finish("succeed", result, text)

    def publish_feedback(self, feedback: Any) -> None:
        minros.logdebug("Publishing feedback for goal, %s", self._goal_ref())
        if not self.goal:
            minros.logerr("Attempt to publish feedback on an uninitialized ServerGoalHandle")
            return
        with self.action_server.lock:
            self.action_server.publish_feedback(self.status_tracker.status, feedback)

    def get_goal(self) -> Any:
        return self.goal.goal if self.goal else None

    def get_goal_id(self) -> Any:
        if not self.goal:
            minros.logerr("Attempt to get a goal id on an uninitialized ServerGoalHandle")
            return GoalID()
        with self.action_server.lock:
            return self.status_tracker.status.goal_id

    def get_goal_status(self) -> Any:
        if not self.goal:
            minros.logerr("Attempt to get goal status on an uninitialized ServerGoalHandle")
            return GoalStatus()
        with self.action_server.lock:
            return self.status_tracker.status

    def __eq__(self, other: object) -> bool:
        if not self.goal or not getattr(other, "goal", None):
            return False
        return self.get_goal_id().id == other.get_goal_id().id  # type: ignore[attr-defined]

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)

    def __hash__(self) -> int:
        return hash(self.get_goal_id().id)

    def set_cancel_requested(self) -> bool:
        """PENDING -> RECALLING or ACTIVE -> PREEMPTING; whether the user should hear of it."""
        if not self.goal:
            return False
        minros.logdebug("Transitioning to a cancel requested state on goal, %s", self._goal_ref())
        with self.action_server.lock:
            status = self.status_tracker.status
            new = server_transition("cancel_request", status.status)
            if new is None:
                return False
            status.status = new
            self.action_server.publish_status()
            return True


def nop_cb(goal_handle: Any) -> None:
    """The default cancel callback: do nothing."""


class ActionServer:
    """Receives goals and cancel requests for namespace ``ns`` and reports their statuses."""

    def __init__(self, ns: str, ActionSpec: type, goal_cb: Callable, cancel_cb: Callable = nop_cb,
                 auto_start: bool = True) -> None:
        if goal_cb is None:
            raise ValueError("ActionServer needs a goal callback")
        self.ns = ns
        self.ActionSpec = ActionSpec
        (self.ActionGoal, self.ActionResult, self.ActionFeedback,
         self.ActionResultType) = action_types(ActionSpec)
        self.goal_sub: Any = None
        self.cancel_sub: Any = None
        self.status_pub: Any = None
        self.result_pub: Any = None
        self.feedback_pub: Any = None
        self.lock = threading.RLock()
        self.status_timer: Any = None
        self.status_list: List[StatusTracker] = []
        self.last_cancel = minros.Time()
        self.status_list_timeout = minros.Duration()
        self.status_frequency = 5.0
        self.id_generator = GoalIDGenerator()
        self.goal_callback = goal_cb
        self.cancel_callback = cancel_cb
        self.auto_start = auto_start
        self.started = False
        if auto_start:
            minros.logwarn("You've passed in true for auto_start to the python action server, you "
                           "should always pass in false to avoid race conditions.")
            self.start()

    def register_goal_callback(self, cb: Callable) -> None:
        self.goal_callback = cb

    def register_cancel_callback(self, cancel_cb: Callable) -> None:
        self.cancel_callback = cancel_cb

    def start(self) -> None:
        with self.lock:
            self.initialize()
            self.started = True
            self.publish_status()

    def stop(self) -> None:
        with self.lock:
            self.started = False
            if self.status_timer is not None:
                self.status_timer.shutdown()
            for topic in (self.goal_sub, self.cancel_sub, self.status_pub, self.feedback_pub,
                          self.result_pub):
                topic.unregister()

    def initialize(self) -> None:
        base = minros.remap_name(self.ns)
        self.pub_queue_size = minros.get_param("actionlib_server_pub_queue_size", 50)
        if self.pub_queue_size < 0:
            self.pub_queue_size = 50
        self.status_pub = minros.Publisher(base + "/status", GoalStatusArray, latch=True,
                                           queue_size=self.pub_queue_size)
        self.result_pub = minros.Publisher(base + "/result", self.ActionResult,
                                           queue_size=self.pub_queue_size)
        self.feedback_pub = minros.Publisher(base + "/feedback", self.ActionFeedback,
                                             queue_size=self.pub_queue_size)
        self.sub_queue_size = minros.get_param("actionlib_server_sub_queue_size", -1)
        if self.sub_queue_size < 0:
            self.sub_queue_size = None
        self.goal_sub = minros.Subscriber(base + "/goal", self.ActionGoal,
                                          callback=self.internal_goal_callback,
                                          queue_size=self.sub_queue_size)
        self.cancel_sub = minros.Subscriber(base + "/cancel", GoalID,
                                            callback=self.internal_cancel_callback,
                                            queue_size=self.sub_queue_size)
        deprecated = base + "/status_frequency"
        if minros.has_param(deprecated):
            self.status_frequency = minros.get_param(deprecated, 5.0)
            minros.logwarn("You're using the deprecated status_frequency parameter, please switch "
                           "to actionlib_status_frequency.")
        else:
            found = minros.search_param("actionlib_status_frequency")
            self.status_frequency = 5.0 if found is None else minros.get_param(found, 5.0)
        self.status_list_timeout = minros.Duration(
            minros.get_param(base + "/status_list_timeout", 5.0))
        if self.status_frequency > 0.0:
            self.status_timer = minros.Timer(minros.Duration(1.0 / self.status_frequency),
                                             self.publish_status_async)

    def publish_result(self, status: Any, result: Any) -> None:
        with self.lock:
            action_result = self.ActionResult()
            action_result.header.stamp = minros.Time.now()
            action_result.status = status
            action_result.result = result
            if not minros.is_shutdown():
                self.result_pub.publish(action_result)
            self.publish_status()

    def publish_feedback(self, status: Any, feedback: Any) -> None:
        with self.lock:
            action_feedback = self.ActionFeedback()
            action_feedback.header.stamp = minros.Time.now()
            action_feedback.status = status
            action_feedback.feedback = feedback
            if not minros.is_shutdown():
                self.feedback_pub.publish(action_feedback)

    def internal_cancel_callback(self, goal_id: Any) -> None:
        with self.lock:
            if not self.started:
                return
            minros.logdebug("The action server has received a new cancel request")
            zero = minros.Time()
            found = False
            for tracker in list(self.status_list):
                status_id = tracker.status.goal_id
                if not cancel_matches(goal_id.id, goal_id.stamp, status_id.id, status_id.stamp, zero):
                    continue
                found = found or goal_id.id == status_id.id
                handle_tracker = tracker.handle_tracker
                if handle_tracker is None:
                    handle_tracker = HandleTrackerDeleter(self, tracker)
                    tracker.handle_tracker = handle_tracker
                    tracker.handle_destruction_time = minros.Time.now()
                handle = ServerGoalHandle(tracker, self, handle_tracker)
                if handle.set_cancel_requested():
                    self.cancel_callback(handle)
            if goal_id.id != "" and not found:
                # the cancel overtook its goal: remember it, so the goal is recalled on arrival
                tracker = StatusTracker(goal_id, GoalStatus.RECALLING)
                tracker.handle_destruction_time = minros.Time.now()
                self.status_list.append(tracker)
            if goal_id.stamp > self.last_cancel:
                self.last_cancel = goal_id.stamp

    def internal_goal_callback(self, goal: Any) -> None:
        with self.lock:
            if not self.started:
                return
            minros.logdebug("The action server has received a new goal request")
            for tracker in self.status_list:
                if goal.goal_id.id != tracker.status.goal_id.id:
                    continue
                minros.logdebug(f"Goal {goal.goal_id.id} was already in the status list with "
                                f"status {tracker.status.status}")
                if tracker.status.status == GoalStatus.RECALLING:
                    tracker.status.status = GoalStatus.RECALLED
                    self.publish_result(tracker.status, self.ActionResultType())
                if tracker.handle_tracker is None:
                    tracker.handle_destruction_time = minros.Time.now()
                return  # a goal we know: no second user callback, no duplicate status
            tracker = StatusTracker(None, None, goal)
            self.status_list.append(tracker)
            tracker.handle_tracker = HandleTrackerDeleter(self, tracker)
            handle = ServerGoalHandle(tracker, self, tracker.handle_tracker)
            if goal.goal_id.stamp != minros.Time() and goal.goal_id.stamp <= self.last_cancel:
                handle.set_canceled(None, "This goal handle was canceled by the action server "
                                          "because its timestamp is before the timestamp of the "
                                          "last cancel request")
            else:
                self.goal_callback(handle)

    def publish_status_async(self, event: Any = None) -> None:
        with self.lock:
            if self.started:
                self.publish_status()

    def publish_status(self) -> None:
        with self.lock:
            now = minros.Time.now()
            zero = minros.Time()
            kept = []
            for tracker in self.status_list:
                expires = tracker.handle_destruction_time
                if expires != zero and expires + self.status_list_timeout < now:
                    minros.logdebug(f"Item {tracker.status.goal_id} with destruction time of "
                                    f"{expires.to_sec():.3f} being removed from list.  Now = "
                                    f"{now.to_sec():.3f}")
                    continue
                kept.append(tracker)
            self.status_list[:] = kept
            array = GoalStatusArray(status_list=[t.status for t in kept])
            array.header.stamp = now
            if not minros.is_shutdown():
                self.status_pub.publish(array)
