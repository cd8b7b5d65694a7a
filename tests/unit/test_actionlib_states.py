"""actionlib's state machines without ROS: the client's CommState steps, the server's status
transitions, cancel matching, and a client goal followed through status/result messages."""

from __future__ import annotations

import pytest

from minros.actionlib.states import (
    INVALID_TRANSITION,
    CommState,
    GoalStatusCodes,
    SimpleGoalState,
    cancel_matches,
    comm_transition,
    server_transition,
)

S = GoalStatusCodes
C = CommState


@pytest.mark.parametrize("state, status, steps", [
    (C.WAITING_FOR_GOAL_ACK, S.SUCCEEDED, (C.ACTIVE, C.WAITING_FOR_RESULT)),
    (C.WAITING_FOR_GOAL_ACK, S.PREEMPTED, (C.ACTIVE, C.PREEMPTING, C.WAITING_FOR_RESULT)),
    (C.PENDING, S.RECALLED, (C.RECALLING, C.WAITING_FOR_RESULT)),
    (C.PENDING, S.PENDING, ()),
    (C.ACTIVE, S.PENDING, (INVALID_TRANSITION,)),
    (C.WAITING_FOR_CANCEL_ACK, S.SUCCEEDED, (C.PREEMPTING, C.WAITING_FOR_RESULT)),
    (C.PREEMPTING, S.ACTIVE, (INVALID_TRANSITION,)),
    (C.DONE, S.SUCCEEDED, ()),
])
def test_comm_transitions(state: int, status: int, steps: tuple) -> None:
    assert comm_transition(state, status) == steps


def test_unknown_status_and_state_are_outside_the_table() -> None:
    assert comm_transition(C.ACTIVE, S.LOST) is None
    assert comm_transition(C.ACTIVE, 42) is None
    assert comm_transition(C.LOST, S.ACTIVE) is None


def test_server_transitions_and_refusals() -> None:
    assert server_transition("accept", S.PENDING) == S.ACTIVE
    assert server_transition("accept", S.RECALLING) == S.PREEMPTING
    assert server_transition("cancel", S.RECALLING) == S.RECALLED
    assert server_transition("cancel", S.PREEMPTING) == S.PREEMPTED
    assert server_transition("succeed", S.PENDING) is None
    assert server_transition("reject", S.ACTIVE) is None
    assert server_transition("cancel_request", S.SUCCEEDED) is None


def test_cancel_matching() -> None:
    zero = 0
    assert cancel_matches("", zero, "g1", 5, zero)          # everything
    assert cancel_matches("g1", zero, "g1", 5, zero)        # by id
    assert not cancel_matches("g2", zero, "g1", 5, zero)
    assert cancel_matches("", 5, "g1", 5, zero)             # at or before the stamp
    assert not cancel_matches("", 4, "g1", 5, zero)


def test_state_names() -> None:
    import actionlib

    assert [actionlib.GoalStatus.to_string(i) for i in (0, 3, 9)] == ["PENDING", "SUCCEEDED", "LOST"]
    assert C.to_string(C.WAITING_FOR_CANCEL_ACK) == "WAITING_FOR_CANCEL_ACK"
    assert SimpleGoalState.to_string(7) == "NO_SUCH_STATE_7"
    assert actionlib.get_name_of_constant(actionlib.TerminalState, 8) == "RECALLED"


def _machine():
    from actionlib.msg import TwoIntsActionGoal
    from actionlib_msgs.msg import GoalID
    from minros.actionlib.client import CommStateMachine

    seen = []
    sent = []
    goal = TwoIntsActionGoal(goal_id=GoalID(id="g1"))
    csm = CommStateMachine(goal, lambda gh: seen.append(gh.get_comm_state()),
                           lambda gh, fb: seen.append(("feedback", fb.__class__.__name__)),
                           sent.append, sent.append)
    return csm, seen, sent


def _status_array(*pairs):
    from actionlib_msgs.msg import GoalID, GoalStatus, GoalStatusArray

    return GoalStatusArray(status_list=[GoalStatus(goal_id=GoalID(id=i), status=s) for i, s in pairs])


def test_client_goal_follows_status_then_result() -> None:
    from actionlib.msg import TwoIntsActionFeedback, TwoIntsActionResult
    from actionlib_msgs.msg import GoalID, GoalStatus
    from minros.actionlib.client import ClientGoalHandle

    csm, seen, _sent = _machine()
    csm.update_status(_status_array(("other", S.ACTIVE)))  # not ours: still waiting for the ack
    assert csm.state == C.WAITING_FOR_GOAL_ACK and seen == []
    csm.update_status(_status_array(("g1", S.ACTIVE)))
    csm.update_feedback(TwoIntsActionFeedback(status=GoalStatus(goal_id=GoalID(id="g1"))))
    result = TwoIntsActionResult(status=GoalStatus(goal_id=GoalID(id="g1"), status=S.SUCCEEDED))
    result.result.sum = 7
    csm.update_result(result)
    assert seen == [C.ACTIVE, ("feedback", "TwoIntsFeedback"), C.WAITING_FOR_RESULT, C.DONE]
    handle = ClientGoalHandle(csm)
    assert handle.get_terminal_state() == S.SUCCEEDED and handle.get_result().sum == 7


def test_goal_the_server_forgets_is_lost() -> None:
    csm, seen, _sent = _machine()
    csm.update_status(_status_array(("g1", S.PENDING)))
    csm.update_status(_status_array())
    assert seen == [C.PENDING, C.DONE] and csm.latest_goal_status.status == S.LOST


def test_cancel_of_a_done_goal_sends_the_request_but_stays_done() -> None:
    from actionlib.msg import TwoIntsActionResult
    from actionlib_msgs.msg import GoalID, GoalStatus
    from minros.actionlib.client import ClientGoalHandle

    csm, seen, sent = _machine()
    csm.update_result(TwoIntsActionResult(status=GoalStatus(goal_id=GoalID(id="g1"),
                                                            status=S.SUCCEEDED)))
    handle = ClientGoalHandle(csm)
    handle.cancel()
    assert sent[-1].id == "g1" and csm.state == C.DONE
    csm.update_status(_status_array(("g1", S.SUCCEEDED)))
    assert handle.get_goal_status() == S.SUCCEEDED and seen[-1] == C.DONE
