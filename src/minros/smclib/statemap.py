"""SMC's Python runtime: the State base class and the FSMContext every generated state
machine derives from (current state, the state stack, the debug trace)."""

from __future__ import annotations

import sys
from typing import IO, List, Optional

__all__ = ["StateUndefinedException", "TransitionUndefinedException", "State", "FSMContext"]


class StateUndefinedException(Exception):
    """A transition was issued while no state is set (from inside a transition action)."""


class TransitionUndefinedException(Exception):
    """The current state (and the default state) defines no such transition."""


class State:
    """A state of a generated machine: a printable name and a unique id."""

    def __init__(self, name: str, id: int) -> None:  # noqa: A002 - SMC's parameter name
        self._name = name
        self._id = id

    def getName(self) -> str:
        return self._name

    def getId(self) -> int:
        return self._id


class FSMContext:
    """Base of generated contexts; the subclass sets the start state in its constructor."""

    def __init__(self, state: Optional[State]) -> None:
        self._state = state
        self._previous_state: Optional[State] = None
        self._state_stack: List[State] = []
        self._transition: Optional[str] = None
        self._debug_flag = False
        self._debug_stream: IO[str] = sys.stderr

    def getDebugFlag(self) -> bool:
        return self._debug_flag

    def setDebugFlag(self, flag: bool) -> None:
        self._debug_flag = flag

    def getDebugStream(self) -> IO[str]:
        return self._debug_stream

    def setDebugStream(self, stream: IO[str]) -> None:
        self._debug_stream = stream

    def _trace(self, what: str) -> None:
        if self._debug_flag:
            self._debug_stream.write(what + "\n")

    def getState(self) -> State:
        if self._state is None:
            raise StateUndefinedException("no current state (inside a transition action?)")
        return self._state

    def isInTransition(self) -> bool:
        return self._state is None

    def getTransition(self) -> Optional[str]:
        return self._transition

    def clearState(self) -> None:
        self._previous_state = self._state
        self._state = None

    def getPreviousState(self) -> Optional[State]:
        return self._previous_state

    def setState(self, state: State) -> None:
        if not isinstance(state, State):
            raise ValueError("state should be a statemap.State")
        self._state = state
        self._trace(f"NEW STATE       : {state.getName()}")

    def isStateStackEmpty(self) -> bool:
        return not self._state_stack

    def getStateStackDepth(self) -> int:
        return len(self._state_stack)

    def pushState(self, state: State) -> None:
        if not isinstance(state, State):
            raise ValueError("state should be a statemap.State")
        if self._state is not None:
            self._state_stack.append(self._state)
        self._state = state
        self._trace(f"PUSH TO STATE   : {state.getName()}")

    def popState(self) -> None:
        if not self._state_stack:
            self._trace("POPPING ON EMPTY STATE STACK.")
            raise ValueError("empty state stack")
        self._state = self._state_stack.pop()
        self._trace(f"POP TO STATE    : {self._state.getName()}")

    def emptyStateStack(self) -> None:
        self._state_stack = []
