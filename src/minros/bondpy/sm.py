"""bondpy.BondSM_sm: the bond state machine as SMC generates it for ROS (state objects over
smclib's statemap, a context whose event methods call the owner's actions), built from the
table in :mod:`.states`, so the Bond and these classes cannot disagree."""

from __future__ import annotations

from typing import Any, Callable, Dict

from minros.bondpy import states
from minros.smclib import statemap

__all__ = ["BondSMState", "SM_Default", "SM_WaitingForSister", "SM_Alive", "SM_AwaitSisterDeath",
           "SM_Dead", "SM", "BondSM_sm"]


class BondSMState(statemap.State):
    """A state of the bond machine: an event it does not define raises
    TransitionUndefinedException naming the state and the event."""

    def Entry(self, fsm: Any) -> None:  # noqa: N802 - SMC's names
        pass

    def Exit(self, fsm: Any) -> None:  # noqa: N802
        pass

    def Default(self, fsm: Any) -> None:  # noqa: N802
        raise statemap.TransitionUndefinedException(
            f"\n\tState: {fsm.getState().getName()}\n\tTransition: {fsm.getTransition()}")


def _undefined(event: str) -> Callable[[Any, Any], None]:
    def handler(self: Any, fsm: Any) -> None:
        self.Default(fsm)

    handler.__name__ = event
    return handler


for _event in states.EVENTS:
    setattr(BondSMState, _event, _undefined(_event))


class SM_Default(BondSMState):  # noqa: N801 - SMC's class names
    pass


def _transition(target: str, actions: tuple) -> Callable[[Any, Any], None]:
    def handler(self: Any, fsm: Any) -> None:
        fsm.getState().Exit(fsm)
        if actions:
            fsm.clearState()
            owner = fsm.getOwner()
            try:
                for action in actions:
                    getattr(owner, action)()
            finally:
                fsm.setState(getattr(SM, target.split(".", 1)[1]))
                fsm.getState().Entry(fsm)
            return
        fsm.setState(getattr(SM, target.split(".", 1)[1]))
        fsm.getState().Entry(fsm)

    return handler


def _state_class(name: str) -> type:
    methods: Dict[str, Any] = {}
    for (state, event), (target, actions) in states.TRANSITIONS.items():
        if state == name:
            methods[event] = _transition(target, actions)
    for state, event in states.STAYS:
        if state == name:
            methods[event] = _transition(state, ())
    return type("SM_" + name.split(".", 1)[1], (SM_Default,), methods)


SM_WaitingForSister = _state_class(states.WAITING)
SM_Alive = _state_class(states.ALIVE)
SM_AwaitSisterDeath = _state_class(states.AWAIT_SISTER_DEATH)
SM_Dead = _state_class(states.DEAD)


class SM:
    """The machine's states (SMC's map class)."""

    WaitingForSister = SM_WaitingForSister(states.WAITING, 0)
    Alive = SM_Alive(states.ALIVE, 1)
    AwaitSisterDeath = SM_AwaitSisterDeath(states.AWAIT_SISTER_DEATH, 2)
    Dead = SM_Dead(states.DEAD, 3)
    Default = SM_Default("SM.Default", -1)


class BondSM_sm(statemap.FSMContext):  # noqa: N801 - SMC's class name
    """The context: ``fsm.SisterAlive()`` etc. run the event in the current state, calling
    the owner's Connected/Heartbeat/SisterDied/Death/StartDying."""

    def __init__(self, owner: Any) -> None:
        super().__init__(SM.WaitingForSister)
        self._owner = owner

    def __getattr__(self, attrib: str) -> Callable[..., None]:
        if attrib.startswith("_"):
            raise AttributeError(attrib)

        def trans_sm(*args: Any) -> None:
            self._transition = attrib
            getattr(self.getState(), attrib)(self, *args)
            self._transition = None

        return trans_sm

    def enterStartState(self) -> None:  # noqa: N802
        self._state.Entry(self)

    def getOwner(self) -> Any:  # noqa: N802
        return self._owner
