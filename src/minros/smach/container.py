"""What every smach container shares: its userdata, the start/transition/termination
callbacks, and the construction stack that ``with sm:`` opens so that ``StateMachine.add``
(a static method, as in ROS) knows which container it adds to."""

from __future__ import annotations

import threading
import traceback
from contextlib import contextmanager
from typing import Any, Callable, Dict, Iterator, List, Sequence, Tuple

from minros.smach import log
from minros.smach.exceptions import (
    InvalidConstructionError,
    InvalidStateError,
    InvalidTransitionError,
)
from minros.smach.state import State
from minros.smach.user_data import UserData, copy_keys

Callback = Tuple[Callable[..., Any], Sequence[Any]]


class Container(State):
    """A state made of states; subclasses define how the children run."""

    # Class-wide: containers are built one at a time (the lock) and may nest (the stack).
    _construction_stack: List[Container] = []
    _construction_lock = threading.RLock()
    _context_kwargs: Dict[str, Any] = {}

    def __init__(self, outcomes: Sequence[str] = (), input_keys: Sequence[str] = (),
                 output_keys: Sequence[str] = ()) -> None:
        super().__init__(outcomes, input_keys, output_keys)
        self.userdata = UserData()
        self._start_cbs: List[Callback] = []
        self._transition_cbs: List[Callback] = []
        self._termination_cbs: List[Callback] = []

    # what each container kind answers (introspection reads these)
    def __getitem__(self, key: str) -> State:
        raise NotImplementedError

    def get_children(self) -> Dict[str, State]:
        raise NotImplementedError

    def set_initial_state(self, initial_states: List[str], userdata: Any) -> None:
        raise NotImplementedError

    def get_initial_states(self) -> List[str]:
        raise NotImplementedError

    def get_active_states(self) -> List[str]:
        raise NotImplementedError

    def get_internal_edges(self) -> List[Tuple[str, str, Any]]:
        """(outcome, from_label, to_label) for each transition inside the container."""
        raise NotImplementedError

    def check_consistency(self) -> None:
        raise NotImplementedError

    def _copy_input_keys(self, parent_ud: Any, ud: Any) -> None:
        copy_keys(parent_ud, ud, self.get_registered_input_keys(), "input")

    def _copy_output_keys(self, ud: Any, parent_ud: Any) -> None:
        copy_keys(ud, parent_ud, self.get_registered_output_keys(), "output")

    # callbacks: cb(userdata, initial_states | active_states, *args), and for termination
    # cb(userdata, terminal_states, outcome, *args)
    def register_start_cb(self, start_cb: Callable[..., Any], cb_args: Sequence[Any] = ()) -> None:
        self._start_cbs.append((start_cb, list(cb_args)))

    def register_transition_cb(self, transition_cb: Callable[..., Any],
                               cb_args: Sequence[Any] = ()) -> None:
        self._transition_cbs.append((transition_cb, list(cb_args)))

    def register_termination_cb(self, termination_cb: Callable[..., Any],
                                cb_args: Sequence[Any] = ()) -> None:
        self._termination_cbs.append((termination_cb, list(cb_args)))

    def _run_cbs(self, kind: str, cbs: List[Callback], *head: Any) -> None:
        # A failing observer (introspection, feedback) must not stop the state machine.
        for cb, args in cbs:
            try:
                cb(self.userdata, *head, *args)
            except Exception:  # noqa: BLE001 - user code
                log.logerr(f"Could not execute {kind} callback: {traceback.format_exc()}")

    def call_start_cbs(self) -> None:
        self._run_cbs("start", self._start_cbs, self.get_initial_states())

    def call_transition_cbs(self) -> None:
        self._run_cbs("transition", self._transition_cbs, self.get_active_states())

    def call_termination_cbs(self, terminal_states: Any, outcome: Any) -> None:
        self._run_cbs("termination", self._termination_cbs, terminal_states, outcome)

    # construction: `with sm:` / `with sm.opened(**kwargs):`
    def __enter__(self) -> Container:
        self.open()
        return self

    def __exit__(self, exc_type: Any, exc_val: Any, exc_tb: Any) -> bool:
        if exc_type is None:
            self.close()
            return False
        # the exception propagates; leave the stack as it was before `with`
        self._pop()
        if exc_type not in (InvalidStateError, InvalidTransitionError):
            log.logerr("Error raised during SMACH container construction: \n"
                       + "".join(traceback.format_exception(exc_type, exc_val, exc_tb)))
        return False

    @contextmanager
    def opened(self, **kwargs: Any) -> Iterator[Container]:
        self.open()
        previous = Container._context_kwargs
        Container._context_kwargs = kwargs
        try:
            yield self
        finally:
            Container._context_kwargs = previous
            self.close()

    def open(self) -> Container:
        Container._construction_lock.acquire()
        Container._construction_stack.append(self)
        return self

    def _pop(self) -> None:
        stack = Container._construction_stack
        if stack and stack[-1] is self:
            stack.pop()
            Container._construction_lock.release()

    def close(self) -> None:
        stack = Container._construction_stack
        if stack and stack[-1] is not self:
            raise InvalidStateError("Attempting to close a container that is not currently open.")
        self._pop()
        try:
            self.check_consistency()
        except (InvalidStateError, InvalidTransitionError):
            log.logerr("Container consistency check failed.")

    def is_opened(self) -> bool:
        stack = Container._construction_stack
        return bool(stack) and stack[-1] is self

    def assert_opened(self, msg: str = "") -> None:
        if not self.is_opened():
            raise InvalidConstructionError(msg or f"{type(self).__name__} is not open: "
                                           "add states inside `with container:`")

    @staticmethod
    def _any_containers_opened() -> bool:
        return bool(Container._construction_stack)

    @classmethod
    def _currently_opened_container(cls) -> Any:
        if not Container._construction_stack:
            raise InvalidStateError(
                f"Attempting to add to a {cls.__name__} but no container is open: "
                f"call {cls.__name__}.add(...) inside `with container:`")
        opened = Container._construction_stack[-1]
        if not isinstance(opened, cls):
            raise InvalidStateError(
                f"Attempting to call a {cls.__name__} construction method while a "
                f"{type(opened).__name__} is the open container.")
        return opened


__all__ = ["Container"]
