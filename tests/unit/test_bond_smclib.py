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


# every (state, event) of bondpy.BondSM_sm: the next state, the owner's actions it ran, or the
# error; run by Debian's generated module and by minros's, which builds it from states.py
BOND_SM_SCRIPT = r'''
import json
from bondpy import BondSM_sm as sm
from smclib import statemap

class Owner:
    def __init__(self):
        self.calls = []
    def __getattr__(self, name):
        return lambda: self.calls.append(name)

out = []
for start in ("WaitingForSister", "Alive", "AwaitSisterDeath", "Dead"):
    for event in ("ConnectTimeout", "Die", "DisconnectTimeout", "HeartbeatTimeout",
                  "SisterAlive", "SisterDead"):
        owner = Owner()
        fsm = sm.BondSM_sm(owner)
        fsm.setState(getattr(sm.SM, start))
        try:
            getattr(fsm, event)()
            out.append([start, event, fsm.getState().getName(), owner.calls])
        except statemap.TransitionUndefinedException as exc:
            out.append([start, event, "undefined", str(exc)])
fsm = sm.BondSM_sm(Owner())
out.append([fsm.getState().getName(), fsm.getState().getId(), sm.SM.Default.getName(),
            sm.SM.Default.getId(), issubclass(sm.SM_Alive, sm.SM_Default),
            issubclass(sm.SM_Default, sm.BondSMState)])
print(json.dumps(out))
'''


@pytest.mark.slow
def test_bond_sm_module_is_rosss_machine() -> None:
    """bondpy.BondSM_sm drives an owner exactly as ROS's SMC-generated module does, undefined
    transitions included (SMC's TransitionUndefinedException and text)."""
    import json
    import subprocess

    from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

    ours = subprocess.run([PYTHON, "-c", BOND_SM_SCRIPT], capture_output=True, text=True,
                          timeout=60)
    assert ours.returncode == 0, ours.stderr
    mine = json.loads(ours.stdout)
    assert ["WaitingForSister", "SisterDead", "SM.Dead", ["Connected", "SisterDied", "Death"]] in mine
    assert mine[0][2] == "SM.Dead" and mine[-1][:2] == ["SM.WaitingForSister", 0]
    require_reference()
    theirs = subprocess.run([REFERENCE_PYTHON, "-c", BOND_SM_SCRIPT], env=reference_env({}),
                            capture_output=True, text=True, timeout=60)
    assert theirs.returncode == 0, theirs.stderr
    assert mine == json.loads(theirs.stdout)
