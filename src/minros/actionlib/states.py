"""actionlib's state machines as data and pure functions (no ROS, no threads).

The action protocol has two sides. The server owns each goal's ``actionlib_msgs/GoalStatus``
and moves it when the user accepts, rejects, succeeds... a goal or when a cancel request
arrives (:data:`SERVER_TRANSITIONS`). The client follows the statuses it receives with its own
*communication state* (:class:`CommState`), stepping through intermediate states when a status
skips some (:func:`comm_transition`). Both tables are the ones actionlib's
DetailedDescription documents and its Python and C++ implementations run.
"""

from __future__ import annotations

from typing import Dict, Tuple, Union


def get_name_of_constant(C: type, n: int) -> str:
    """The name of the state constant of class ``C`` whose value is ``n``."""
    for name, value in vars(C).items():
        if name.isupper() and isinstance(value, int) and not isinstance(value, bool) and value == n:
            return name
    return f"NO_SUCH_STATE_{n}"


class _Named:
    """Integer constants with ``to_string(value)``, as actionlib's state classes offer."""

    to_string = classmethod(get_name_of_constant)


class GoalStatusCodes(_Named):
    """The values of ``actionlib_msgs/GoalStatus.status`` (its constants, by name)."""

    PENDING = 0
    ACTIVE = 1
    PREEMPTED = 2
    SUCCEEDED = 3
    ABORTED = 4
    REJECTED = 5
    PREEMPTING = 6
    RECALLING = 7
    RECALLED = 8
    LOST = 9


S = GoalStatusCodes
#: statuses after which a goal never changes again
TERMINAL_STATUSES = frozenset({S.PREEMPTED, S.SUCCEEDED, S.ABORTED, S.REJECTED, S.RECALLED,
                               S.LOST})


class CommState(_Named):
    """The client's view of the conversation about one goal."""

    WAITING_FOR_GOAL_ACK = 0
    PENDING = 1
    ACTIVE = 2
    WAITING_FOR_RESULT = 3
    WAITING_FOR_CANCEL_ACK = 4
    RECALLING = 5
    PREEMPTING = 6
    DONE = 7
    LOST = 8


class TerminalState(_Named):
    """The terminal statuses a client can report for a goal."""

    RECALLED = S.RECALLED
    REJECTED = S.REJECTED
    PREEMPTED = S.PREEMPTED
    ABORTED = S.ABORTED
    SUCCEEDED = S.SUCCEEDED
    LOST = S.LOST


class SimpleGoalState(_Named):
    """SimpleActionClient's coarse view: pending, active or done."""

    PENDING = 0
    ACTIVE = 1
    DONE = 2


# ---------------------------------------------------------------------------------------------
# client: communication state x received status -> states to pass through

NO_TRANSITION = -1
INVALID_TRANSITION = -2

C = CommState
_WR = C.WAITING_FOR_RESULT
Step = Union[int, Tuple[int, ...]]


def _row(pending: Step, active: Step, rejected: Step, recalling: Step, recalled: Step,
         preempted: Step, succeeded: Step, aborted: Step, preempting: Step) -> Dict[int, Tuple[int, ...]]:
    """One row of the client table, in GoalStatus order; each entry becomes a tuple of states
    (empty for "stay", ``(INVALID_TRANSITION,)`` for a protocol violation)."""
    cells = {S.PENDING: pending, S.ACTIVE: active, S.REJECTED: rejected, S.RECALLING: recalling,
             S.RECALLED: recalled, S.PREEMPTED: preempted, S.SUCCEEDED: succeeded,
             S.ABORTED: aborted, S.PREEMPTING: preempting}
    row = {}
    for status, step in cells.items():
        if step == NO_TRANSITION:
            row[status] = ()
        elif isinstance(step, tuple):
            row[status] = step
        else:
            row[status] = (step,)
    return row


_N, _X = NO_TRANSITION, INVALID_TRANSITION
#: For each communication state, the states a received status leads through (in order).
COMM_TRANSITIONS: Dict[int, Dict[int, Tuple[int, ...]]] = {
    C.WAITING_FOR_GOAL_ACK: _row(
        C.PENDING, C.ACTIVE, (C.PENDING, _WR), (C.PENDING, C.RECALLING), (C.PENDING, _WR),
        (C.ACTIVE, C.PREEMPTING, _WR), (C.ACTIVE, _WR), (C.ACTIVE, _WR), (C.ACTIVE, C.PREEMPTING)),
    C.PENDING: _row(
        _N, C.ACTIVE, _WR, C.RECALLING, (C.RECALLING, _WR),
        (C.ACTIVE, C.PREEMPTING, _WR), (C.ACTIVE, _WR), (C.ACTIVE, _WR), (C.ACTIVE, C.PREEMPTING)),
    C.ACTIVE: _row(
        _X, _N, _X, _X, _X, (C.PREEMPTING, _WR), _WR, _WR, C.PREEMPTING),
    C.WAITING_FOR_RESULT: _row(
        _X, _N, _N, _X, _N, _N, _N, _N, _X),
    C.WAITING_FOR_CANCEL_ACK: _row(
        _N, _N, _WR, C.RECALLING, (C.RECALLING, _WR),
        (C.PREEMPTING, _WR), (C.PREEMPTING, _WR), (C.PREEMPTING, _WR), C.PREEMPTING),
    C.RECALLING: _row(
        _X, _X, _WR, _N, _WR, (C.PREEMPTING, _WR), (C.PREEMPTING, _WR), (C.PREEMPTING, _WR),
        C.PREEMPTING),
    C.PREEMPTING: _row(
        _X, _X, _X, _X, _X, _WR, _WR, _WR, _N),
    C.DONE: _row(
        _X, _X, _N, _X, _N, _N, _N, _N, _X),
}


def comm_transition(state: int, status: int) -> Tuple[int, ...] | None:
    """The communication states to pass through when a goal in ``state`` gets ``status``.

    Empty tuple: nothing changes. ``(INVALID_TRANSITION,)``: the server broke the protocol.
    None: ``state`` or ``status`` is outside the table (a status such as LOST, or garbage).
    """
    row = COMM_TRANSITIONS.get(state)
    if row is None:
        return None
    return row.get(status)


# ---------------------------------------------------------------------------------------------
# server: what each goal-handle operation does to the goal's status

#: operation -> {current status: new status}; any other current status is refused
SERVER_TRANSITIONS: Dict[str, Dict[int, int]] = {
    "accept": {S.PENDING: S.ACTIVE, S.RECALLING: S.PREEMPTING},
    "cancel": {S.PENDING: S.RECALLED, S.RECALLING: S.RECALLED,
               S.ACTIVE: S.PREEMPTED, S.PREEMPTING: S.PREEMPTED},
    "reject": {S.PENDING: S.REJECTED, S.RECALLING: S.REJECTED},
    "abort": {S.ACTIVE: S.ABORTED, S.PREEMPTING: S.ABORTED},
    "succeed": {S.ACTIVE: S.SUCCEEDED, S.PREEMPTING: S.SUCCEEDED},
    "cancel_request": {S.PENDING: S.RECALLING, S.ACTIVE: S.PREEMPTING},
}

#: actionlib's error text when an operation is refused (it ends with the current status)
SERVER_REFUSALS: Dict[str, str] = {
    "accept": "To transition to an active state, the goal must be in a pending or recalling "
              "state, it is currently in state: %d",
    "cancel": "To transition to a cancelled state, the goal must be in a pending, recalling, "
              "active, or preempting state, it is currently in state: %d",
    "reject": "To transition to a rejected state, the goal must be in a pending or recalling "
              "state, it is currently in state: %d",
    "abort": "To transition to an aborted state, the goal must be in a preempting or active "
             "state, it is currently in state: %d",
    "succeed": "To transition to a succeeded state, the goal must be in a preempting or active "
               "state, it is currently in state: %d",
}


def server_transition(operation: str, status: int) -> int | None:
    """The status a goal in ``status`` gets from ``operation``, or None if it is refused."""
    return SERVER_TRANSITIONS[operation].get(status)


def cancel_matches(cancel_id: str, cancel_stamp: object, goal_id: str, goal_stamp: object,
                   zero_stamp: object) -> bool:
    """Whether a cancel request ``(cancel_id, cancel_stamp)`` applies to a goal.

    An empty id with a zero stamp cancels everything; a matching id cancels that goal; a
    non-zero stamp cancels every goal stamped at or before it.
    """
    if cancel_id == "" and cancel_stamp == zero_stamp:
        return True
    if cancel_id == goal_id:
        return True
    return cancel_stamp != zero_stamp and goal_stamp <= cancel_stamp  # type: ignore[operator]
