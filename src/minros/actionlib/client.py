"""The action client: goal handles, their communication state machines, ActionClient.

Topics (under the action namespace, as actionlib names them): the client publishes
``goal`` (``*ActionGoal``) and ``cancel`` (``actionlib_msgs/GoalID``) and subscribes to
``status`` (``GoalStatusArray``), ``result`` and ``feedback``. Each sent goal gets a
:class:`CommStateMachine` that follows the statuses the server reports; the user holds
:class:`ClientGoalHandle` objects, and a goal stops being tracked once no handle refers to it.
"""

from __future__ import annotations

import threading
import time
import weakref
from typing import Any, Callable, List

import minros
from actionlib_msgs.msg import GoalID, GoalStatus, GoalStatusArray

from .states import (
    INVALID_TRANSITION,
    TERMINAL_STATUSES,
    CommState,
    GoalStatusCodes,
    comm_transition,
)


class ActionException(Exception):
    """A type given as an action is not one (it lacks ``action_goal`` and friends)."""


def action_types(action_spec: type) -> tuple:
    """``(ActionGoal, ActionResult, ActionFeedback, Result)`` classes of an ``*Action`` type."""
    try:
        spec = action_spec()
        return (type(spec.action_goal), type(spec.action_result), type(spec.action_feedback),
                type(spec.action_result.result))
    except AttributeError:
        raise ActionException(f"Type is not an action spec: {action_spec}") from None


def _status_of(status_array: Any, goal_id: str) -> Any:
    for status in status_array.status_list:
        if status.goal_id.id == goal_id:
            return status
    return None


class CommStateMachine:
    """The client-side state of one goal, moved by status, result and feedback messages."""

    def __init__(self, action_goal: Any, transition_cb: Callable | None, feedback_cb: Callable | None,
                 send_goal_fn: Callable, send_cancel_fn: Callable) -> None:
        self.action_goal = action_goal
        self.transition_cb = transition_cb
        self.feedback_cb = feedback_cb
        self.send_goal_fn = send_goal_fn
        self.send_cancel_fn = send_cancel_fn
        self.state = CommState.WAITING_FOR_GOAL_ACK
        self.mutex = threading.RLock()
        self.latest_goal_status = GoalStatus(status=GoalStatus.PENDING)
        self.latest_result: Any = None

    def __eq__(self, other: object) -> bool:
        return isinstance(other, CommStateMachine) and \
            self.action_goal.goal_id.id == other.action_goal.goal_id.id

    def __hash__(self) -> int:
        return hash(self.action_goal.goal_id.id)

    @property
    def goal_id(self) -> str:
        return self.action_goal.goal_id.id

    def set_state(self, state: int) -> None:
        minros.logdebug("Transitioning CommState from %s to %s", CommState.to_string(self.state),
                        CommState.to_string(state))
        self.state = state

    def transition_to(self, state: int) -> None:
        minros.logdebug("Transitioning to %s (from %s, goal: %s)", CommState.to_string(state),
                        CommState.to_string(self.state), self.goal_id)
        self.state = state
        if self.transition_cb:
            self.transition_cb(ClientGoalHandle(self))

    def update_status(self, status_array: Any) -> None:
        with self.mutex:
            if self.state == CommState.DONE:
                return
            status = _status_of(status_array, self.goal_id)
            if status is None:
                # the server has forgotten a goal it had acknowledged
                if self.state not in (CommState.WAITING_FOR_GOAL_ACK, CommState.WAITING_FOR_RESULT,
                                      CommState.DONE):
                    self.latest_goal_status.status = GoalStatus.LOST
                    self.transition_to(CommState.DONE)
                return
            self.latest_goal_status = status
            steps = comm_transition(self.state, status.status)
            if steps is None:
                minros.logerr(f"Got an unknown status from the ActionServer: {status.status}")
            elif steps == (INVALID_TRANSITION,):
                minros.logerr(f"Invalid goal status transition from {CommState.to_string(self.state)}"
                              f" to {GoalStatusCodes.to_string(status.status)}")
            else:
                for step in steps:
                    self.transition_to(step)

    def update_result(self, action_result: Any) -> None:
        if action_result.status.goal_id.id != self.goal_id:
            return
        with self.mutex:
            self.latest_goal_status = action_result.status
            self.latest_result = action_result
            if self.state == CommState.DONE:
                minros.logerr("Got a result when we were already in the DONE state")
                return
            if self.state not in _RESULT_ACCEPTING:
                minros.logerr(f"In a funny state: {self.state}")
                return
            # the result carries the final status: first catch up with it, then finish
            self.update_status(GoalStatusArray(status_list=[action_result.status]))
            self.transition_to(CommState.DONE)

    def update_feedback(self, action_feedback: Any) -> None:
        if action_feedback.status.goal_id.id != self.goal_id:
            return
        if self.feedback_cb and self.state != CommState.DONE:
            self.feedback_cb(ClientGoalHandle(self), action_feedback.feedback)


_RESULT_ACCEPTING = frozenset({
    CommState.WAITING_FOR_GOAL_ACK, CommState.WAITING_FOR_CANCEL_ACK, CommState.PENDING,
    CommState.ACTIVE, CommState.WAITING_FOR_RESULT, CommState.RECALLING, CommState.PREEMPTING})


class ClientGoalHandle:
    """The user's handle on a sent goal; equal handles track the same goal."""

    def __init__(self, comm_state_machine: CommStateMachine | None) -> None:
        self.comm_state_machine = comm_state_machine

    def __eq__(self, other: object) -> bool:
        if not other:
            return False
        return self.comm_state_machine == getattr(other, "comm_state_machine", None)

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)

    def __hash__(self) -> int:
        return hash(self.comm_state_machine)

    def cancel(self) -> None:
        """Ask the server to cancel this goal (a goal already done only gets the message)."""
        csm = self.comm_state_machine
        if csm is None:
            minros.logerr("Trying to cancel an inactive ClientGoalHandle.")
            return
        with csm.mutex:
            csm.send_cancel_fn(GoalID(stamp=minros.Time(0), id=csm.goal_id))
            # Debian's Python client would also leave DONE here and then log errors when the
            # server's status for the finished goal arrives; a finished goal stays finished
            # (as in the C++ client).
            if csm.state != CommState.DONE:
                csm.transition_to(CommState.WAITING_FOR_CANCEL_ACK)

    def get_comm_state(self) -> int:
        if not self.comm_state_machine:
            minros.logerr("Trying to get_comm_state on an inactive ClientGoalHandle.")
            return CommState.LOST
        return self.comm_state_machine.state

    def get_goal_status(self) -> int:
        if not self.comm_state_machine:
            minros.logerr("Trying to get_goal_status on an inactive ClientGoalHandle.")
            return GoalStatus.PENDING
        return self.comm_state_machine.latest_goal_status.status

    def get_goal_status_text(self) -> str:
        if not self.comm_state_machine:
            minros.logerr("Trying to get_goal_status_text on an inactive ClientGoalHandle.")
            return "ERROR: Trying to get_goal_status_text on an inactive ClientGoalHandle."
        return self.comm_state_machine.latest_goal_status.text

    def get_result(self) -> Any:
        if not self.comm_state_machine:
            minros.logerr("Trying to get_result on an inactive ClientGoalHandle.")
            return None
        result = self.comm_state_machine.latest_result
        return None if result is None else result.result

    def get_terminal_state(self) -> int:
        csm = self.comm_state_machine
        if not csm:
            minros.logerr("Trying to get_terminal_state on an inactive ClientGoalHandle.")
            return GoalStatus.LOST
        with csm.mutex:
            if csm.state != CommState.DONE:
                minros.logwarn("Asking for the terminal state when we're in [%s]",
                               CommState.to_string(csm.state))
            status = csm.latest_goal_status.status
            if status in TERMINAL_STATUSES:
                return status
            minros.logerr("Asking for a terminal state, but the goal status is %d", status)
            return GoalStatus.LOST


#: the number the next goal id carries (actionlib's g_goal_id)
_next_goal_number = 1
_goal_counter_lock = threading.Lock()


def next_goal_number() -> int:
    """The number the next goal id an ActionClient makes will carry."""
    return _next_goal_number


class GoalManager:
    """The goals of one ActionClient; it keeps only weak references to their state machines."""

    def __init__(self, action_spec: type) -> None:
        self.list_mutex = threading.RLock()
        self.statuses: List[weakref.ref] = []
        self.send_goal_fn: Callable | None = None
        self.cancel_fn: Callable | None = None
        self.ActionSpec = action_spec
        self.ActionGoal, self.ActionResult, self.ActionFeedback, _ = action_types(action_spec)

    def _generate_id(self) -> Any:
        global _next_goal_number
        with _goal_counter_lock:
            number, _next_goal_number = _next_goal_number, _next_goal_number + 1
        now = minros.Time.now()
        return GoalID(id=f"{minros.get_caller_id()}-{number}-{now.to_sec():.3f}", stamp=now)

    def register_send_goal_fn(self, fn: Callable) -> None:
        self.send_goal_fn = fn

    def register_cancel_fn(self, fn: Callable) -> None:
        self.cancel_fn = fn

    def init_goal(self, goal: Any, transition_cb: Callable | None = None,
                  feedback_cb: Callable | None = None) -> ClientGoalHandle:
        from std_msgs.msg import Header

        action_goal = self.ActionGoal(header=Header(), goal_id=self._generate_id(), goal=goal)
        action_goal.header.stamp = minros.get_rostime()
        csm = CommStateMachine(action_goal, transition_cb, feedback_cb, self.send_goal_fn,
                               self.cancel_fn)
        with self.list_mutex:
            self.statuses.append(weakref.ref(csm))
        self.send_goal_fn(action_goal)
        return ClientGoalHandle(csm)

    def _get_live_statuses(self) -> List[CommStateMachine]:
        with self.list_mutex:
            live = [ref() for ref in self.statuses]
            return [csm for csm in live if csm is not None]

    def update_statuses(self, status_array: Any) -> None:
        with self.list_mutex:
            self.statuses = [ref for ref in self.statuses if ref() is not None]
        for csm in self._get_live_statuses():
            csm.update_status(status_array)

    def update_results(self, action_result: Any) -> None:
        for csm in self._get_live_statuses():
            csm.update_result(action_result)

    def update_feedbacks(self, action_feedback: Any) -> None:
        for csm in self._get_live_statuses():
            csm.update_feedback(action_feedback)


class ActionClient:
    """Sends goals to the action server in namespace ``ns`` and tracks them."""

    def __init__(self, ns: str, ActionSpec: type) -> None:
        self.ns = ns
        self.last_status_msg: Any = None
        self.ActionSpec = ActionSpec
        self.ActionGoal, self.ActionResult, self.ActionFeedback, _ = action_types(ActionSpec)
        base = minros.remap_name(ns)
        self.pub_queue_size = minros.get_param("actionlib_client_pub_queue_size", 10)
        if self.pub_queue_size < 0:
            self.pub_queue_size = 10
        self.pub_goal = minros.Publisher(base + "/goal", self.ActionGoal,
                                         queue_size=self.pub_queue_size)
        self.pub_cancel = minros.Publisher(base + "/cancel", GoalID, queue_size=self.pub_queue_size)
        self.manager = GoalManager(ActionSpec)
        self.manager.register_send_goal_fn(self.pub_goal.publish)
        self.manager.register_cancel_fn(self.pub_cancel.publish)
        self.sub_queue_size = minros.get_param("actionlib_client_sub_queue_size", -1)
        if self.sub_queue_size < 0:
            self.sub_queue_size = None
        self.status_sub = minros.Subscriber(base + "/status", GoalStatusArray, callback=self._status_cb,
                                            queue_size=self.sub_queue_size)
        self.result_sub = minros.Subscriber(base + "/result", self.ActionResult,
                                            callback=self._result_cb, queue_size=self.sub_queue_size)
        self.feedback_sub = minros.Subscriber(base + "/feedback", self.ActionFeedback,
                                              callback=self._feedback_cb, queue_size=self.sub_queue_size)
        self._server_uris: dict = {}

    def stop(self) -> None:
        for topic in (self.pub_goal, self.pub_cancel, self.status_sub, self.result_sub,
                      self.feedback_sub):
            topic.unregister()

    def send_goal(self, goal: Any, transition_cb: Callable | None = None,
                  feedback_cb: Callable | None = None) -> ClientGoalHandle:
        return self.manager.init_goal(goal, transition_cb, feedback_cb)

    def cancel_all_goals(self) -> None:
        self.pub_cancel.publish(GoalID(stamp=minros.Time.from_sec(0.0), id=""))

    def cancel_goals_at_and_before_time(self, time: Any) -> None:
        self.pub_cancel.publish(GoalID(stamp=time, id=""))

    def wait_for_action_server_to_start(self, timeout: Any = None) -> bool:
        return self.wait_for_server(timeout)

    def wait_for_server(self, timeout: Any = None) -> bool:
        """Block until the server that sends our status messages is connected on all five
        topics; a zero timeout waits forever. Returns whether it connected."""
        timeout = _duration(timeout)
        deadline = minros.get_rostime() + timeout
        while not minros.is_shutdown():
            status = self.last_status_msg
            if status is not None:
                header = getattr(status, "_connection_header", None) or {}
                server_id = header.get("callerid", "")
                if server_id and self._connected_to(server_id):
                    return True
            if timeout != minros.Duration(0) and minros.get_rostime() >= deadline:
                break
            # connection set-up has no event to wait on; actionlib polls every 10 ms too
            time.sleep(0.01)
        return False

    def _connected_to(self, server_id: str) -> bool:
        """Whether goal/cancel reach ``server_id`` and result/feedback come from it."""
        for pub in (self.pub_goal, self.pub_cancel):
            if server_id not in _peers(pub):
                return False
        uri, looked_up = self._server_uris.get(server_id, (None, 0.0))
        if uri is None or not self._results_from(uri):
            if time.monotonic() - looked_up < 0.5:
                return False
            # first time, or the server restarted under the same name: ask the master again
            uri = _lookup_node(server_id)
            self._server_uris[server_id] = (uri, time.monotonic())
        return uri is not None and self._results_from(uri)

    def _results_from(self, uri: str) -> bool:
        return all(uri in _peers(sub) for sub in (self.result_sub, self.feedback_sub))

    def _status_cb(self, msg: Any) -> None:
        self.last_status_msg = msg
        self.manager.update_statuses(msg)

    def _result_cb(self, msg: Any) -> None:
        self.manager.update_results(msg)

    def _feedback_cb(self, msg: Any) -> None:
        self.manager.update_feedbacks(msg)


def _duration(value: Any) -> Any:
    """A Duration from actionlib's timeout arguments (None or 0 mean "forever")."""
    if value is None:
        return minros.Duration(0)
    if isinstance(value, (int, float)):
        return minros.Duration.from_sec(value)
    return value


def _peers(topic: Any) -> set:
    """The peers of a Publisher or Subscriber, from its getBusInfo rows (connection id, peer,
    direction, ...): for a publisher the subscribers' caller ids, for a subscriber the
    publishers' XML-RPC URIs."""
    impl = getattr(topic, "impl", None)
    return {row[1] for row in impl.get_stats_info()} if impl is not None else set()


def _lookup_node(name: str) -> str | None:
    from minros import node

    try:
        return node.master().lookup_node(name)
    except Exception:  # noqa: BLE001 - unknown, or an unreachable master: "not yet"
        return None
