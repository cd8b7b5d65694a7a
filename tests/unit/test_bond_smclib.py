"""The bond state table and smclib's FSMContext, without sockets."""

from __future__ import annotations

import io

import pytest

from minros.bondpy import states
from smclib import statemap


@pytest.mark.parametrize("state, event, expected", [
    (states.WAITING, "SisterAlive", (states.ALIVE, ("Connected",))),
    (states.WAITING, "SisterDead", (states.DEAD, ("Connected", "SisterDied", "Death"))),
    (states.WAITING, "HeartbeatTimeout", (states.WAITING, ())),
    (states.ALIVE, "SisterAlive", (states.ALIVE, ("Heartbeat",))),
    (states.ALIVE, "Die", (states.AWAIT_SISTER_DEATH, ("StartDying",))),
    (states.AWAIT_SISTER_DEATH, "SisterAlive", (states.AWAIT_SISTER_DEATH, ())),
    (states.AWAIT_SISTER_DEATH, "DisconnectTimeout", (states.DEAD, ("Death",))),
    (states.DEAD, "SisterAlive", (states.DEAD, ())),
])
def test_bond_transitions(state, event, expected) -> None:
    assert states.step(state, event) == expected


def test_fsm_context_states_stack_and_trace() -> None:
    a, b = statemap.State("M.A", 0), statemap.State("M.B", 1)
    trace = io.StringIO()
    fsm = statemap.FSMContext(a)
    fsm.setDebugFlag(True)
    fsm.setDebugStream(trace)
    fsm.pushState(b)
    assert fsm.getState() is b and fsm.getStateStackDepth() == 1
    fsm.popState()
    assert fsm.getState() is a and fsm.isStateStackEmpty()
    fsm.clearState()
    assert fsm.isInTransition() and fsm.getPreviousState() is a
    with pytest.raises(statemap.StateUndefinedException):
        fsm.getState()
    with pytest.raises(ValueError):
        fsm.popState()
    with pytest.raises(ValueError):
        fsm.setState("M.A")  # type: ignore[arg-type]
    assert trace.getvalue().splitlines() == ["PUSH TO STATE   : M.B", "POP TO STATE    : M.A",
                                             "POPPING ON EMPTY STATE STACK."]
