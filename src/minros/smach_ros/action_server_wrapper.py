"""ActionServerWrapper: a smach container offered as an actionlib action server."""

from __future__ import annotations

import copy
import traceback
from typing import Any, Dict, Sequence

import minros
from minros import smach
from minros.actionlib import SimpleActionServer

__all__ = ["ActionServerWrapper"]


class ActionServerWrapper:
    """Run ``wrapped_container`` for each goal of the action ``server_name``.

    The goal goes into the container's userdata under ``goal_key`` (and its fields under
    their own names with ``expand_goal_slots``, or renamed through ``goal_slots_map``); each
    transition publishes ``ud[feedback_key]`` as feedback; the result is ``ud[result_key]``
    (fields filled from ``result_slots_map`` or, with ``pack_result_slots``, from like-named
    keys). The container's outcome picks the goal's end: one of ``succeeded_outcomes``,
    ``preempted_outcomes``, anything else aborts. A cancel preempts the container.
    """

    def __init__(self, server_name: str, action_spec: type, wrapped_container: smach.Container,
                 succeeded_outcomes: Sequence[str] = (), aborted_outcomes: Sequence[str] = (),
                 preempted_outcomes: Sequence[str] = (), goal_key: str = "action_goal",
                 feedback_key: str = "action_feedback", result_key: str = "action_result",
                 goal_slots_map: Dict[str, str] | None = None,
                 feedback_slots_map: Dict[str, str] | None = None,
                 result_slots_map: Dict[str, str] | None = None,
                 expand_goal_slots: bool = False, pack_result_slots: bool = False) -> None:
        self.wrapped_container = wrapped_container
        self.wrapped_container.register_transition_cb(self.transition_cb)
        self.wrapped_container.register_termination_cb(self.termination_cb)
        self.userdata = smach.UserData()
        self._goal_key = goal_key
        self._feedback_key = feedback_key
        self._result_key = result_key
        self._goal_slots_map = dict(goal_slots_map or {})
        self._feedback_slots_map = dict(feedback_slots_map or {})
        self._result_slots_map = dict(result_slots_map or {})
        self._expand_goal_slots = expand_goal_slots
        self._pack_result_slots = pack_result_slots
        spec = action_spec()
        self.userdata[goal_key] = copy.copy(spec.action_goal.goal)
        self.userdata[result_key] = copy.copy(spec.action_result.result)
        self.userdata[feedback_key] = copy.copy(spec.action_feedback.feedback)
        self._result_type = type(spec.action_result.result)
        self._server_name = server_name
        self._action_spec = action_spec
        self._action_server = SimpleActionServer(server_name, action_spec,
                                                 execute_cb=self.execute_cb, auto_start=False)
        self._succeeded_outcomes = set(succeeded_outcomes)
        self._aborted_outcomes = set(aborted_outcomes)
        self._preempted_outcomes = set(preempted_outcomes)
        together = self._succeeded_outcomes | self._aborted_outcomes | self._preempted_outcomes
        if len(together) != len(succeeded_outcomes) + len(aborted_outcomes) + len(preempted_outcomes):
            minros.logerr("Succeeded, aborted, and preempted outcome lists were not mutually "
                          "disjoint... expect undefined behavior.")

    def run_server(self) -> None:
        """Start the action server (it does not block: spin the node afterwards)."""
        self._action_server.register_preempt_callback(self.preempt_cb)
        self._action_server.start()
        minros.loginfo(f"Started SMACH action server wrapper, advertising as "
                       f"'{self._server_name}'")

    def transition_cb(self, userdata: Any, active_states: Any) -> None:
        self.publish_feedback(userdata)

    def termination_cb(self, userdata: Any, terminal_states: Any, container_outcome: Any) -> None:
        minros.logdebug(f"Wrapped state machine has terminated with final state: "
                        f"{terminal_states} and container outcome: {container_outcome}")

    def publish_feedback(self, userdata: Any) -> None:
        if self._feedback_key in userdata:
            self._action_server.publish_feedback(userdata[self._feedback_key])

    def execute_cb(self, goal: Any) -> None:
        """Run the container for ``goal`` and end the goal by its outcome."""
        if self._expand_goal_slots:
            for slot in goal.__slots__:
                self.userdata[slot] = getattr(goal, slot)
        self.userdata[self._goal_key] = goal
        for from_key, to_key in self._goal_slots_map.items():
            self.userdata[to_key] = getattr(goal, from_key)
        self.userdata[self._result_key] = self._result_type()
        try:
            outcome = self.wrapped_container.execute(smach.Remapper(
                self.userdata, self.wrapped_container.get_registered_input_keys(),
                self.wrapped_container.get_registered_output_keys(), {}))
        except smach.InvalidUserCodeError:
            minros.logerr("Exception thrown while executing wrapped container.")
            self._action_server.set_aborted()
            return
        except Exception:  # noqa: BLE001 - the goal aborts, the server keeps serving
            minros.logerr("Exception thrown:while executing wrapped container: "
                          + traceback.format_exc())
            self._action_server.set_aborted()
            return
        result = self.userdata[self._result_key]
        for from_key, to_key in self._result_slots_map.items():
            setattr(result, from_key, self.userdata[to_key])
        if self._pack_result_slots:
            for slot in result.__slots__:
                if slot in self.userdata:
                    setattr(result, slot, self.userdata[slot])
        if outcome in self._succeeded_outcomes:
            minros.loginfo("SUCCEEDED")
            self._action_server.set_succeeded(result)
        elif outcome in self._preempted_outcomes:
            minros.loginfo("PREEMPTED")
            self._action_server.set_preempted(result)
        else:
            minros.loginfo("ABORTED")
            self._action_server.set_aborted(result)

    def preempt_cb(self) -> None:
        minros.loginfo("Preempt on state machine requested!")
        self.wrapped_container.request_preempt()
