"""Iterator: runs one contained state once per item of an iterable (the item in the
container's userdata under ``it_label``) until the items run out or an outcome breaks."""

from __future__ import annotations

import traceback
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple

from minros.smach import log
from minros.smach.container import Container
from minros.smach.exceptions import InvalidUserCodeError
from minros.smach.state import State


class Iterator(Container):
    """Loop container; ``exhausted_outcome`` (added to the outcomes) ends a full run."""

    def __init__(self, outcomes: Sequence[str], input_keys: Sequence[str],
                 output_keys: Sequence[str], it: Any = (), it_label: str = "it_data",
                 exhausted_outcome: str = "exhausted") -> None:
        outcomes = list(outcomes)
        if exhausted_outcome not in outcomes:
            outcomes.append(exhausted_outcome)
        super().__init__(outcomes, input_keys, output_keys)
        self._items = it
        self._items_label = it_label
        self._is_running = False
        self._state_label = ""
        self._state: Optional[State] = None
        self._loop_outcomes: List[str] = []
        self._break_outcomes: List[str] = []
        self._final_outcome_map: Dict[str, str] = {}
        self._exhausted_outcome = exhausted_outcome

    @staticmethod
    def set_iteritems(it: Any, it_label: str = "it_data") -> None:
        """The iterable (or a function returning one, called at each run) of the open Iterator."""
        self = Iterator._currently_opened_container()
        self._items = it
        self._items_label = it_label

    @staticmethod
    def set_contained_state(label: str, state: State, loop_outcomes: Sequence[str] = (),
                            break_outcomes: Sequence[str] = (),
                            final_outcome_map: Optional[Mapping[str, str]] = None) -> State:
        """The state the open Iterator runs. ``break_outcomes`` end the loop (every other
        outcome continues); without them, outcomes not in ``loop_outcomes`` end it.
        ``final_outcome_map`` renames the outcome that ends the loop."""
        self = Iterator._currently_opened_container()
        self._state_label = label
        self._state = state
        outcomes = state.get_registered_outcomes()
        if loop_outcomes and break_outcomes:
            log.logwarn("Both loop_outcomes and break_outcomes were specified when constructing "
                        "SMACH iterator container.")
        if break_outcomes:
            self._break_outcomes = list(break_outcomes)
            self._loop_outcomes = [o for o in outcomes if o not in break_outcomes]
        else:
            self._loop_outcomes = list(loop_outcomes)
            self._break_outcomes = [o for o in outcomes if o not in loop_outcomes]
        self._final_outcome_map = dict(final_outcome_map or {})
        return state

    def _iterable(self) -> Iterable[Any]:
        return self._items() if callable(self._items) else self._items

    def execute(self, parent_ud: Any = None) -> Optional[str]:
        if self._state is None:
            raise InvalidUserCodeError("Iterator has no contained state: call "
                                       "Iterator.set_contained_state(...) inside `with it:`")
        self._is_running = True
        self._copy_input_keys(parent_ud, self.userdata)
        self.call_start_cbs()
        outcome: Optional[str] = self._exhausted_outcome
        try:
            for item in self._iterable():
                if log.is_shutdown():
                    break
                log.loginfo(f"Iterating {item} of {self._items}")
                self.userdata[self._items_label] = item
                try:
                    outcome = self._state.execute(self.userdata)
                except InvalidUserCodeError:
                    log.logerr(f"Could not execute Iterator state '{self._state_label}'")
                    raise
                except Exception:  # noqa: BLE001 - user code
                    raise InvalidUserCodeError(
                        f"Could not execute iterator state '{self._state_label}' of type "
                        f"'{self._state}': " + traceback.format_exc()) from None
                if self._preempt_requested or outcome in self._break_outcomes or (
                        self._loop_outcomes and outcome not in self._loop_outcomes):
                    self._preempt_requested = False
                    break
                self.call_transition_cbs()
            else:
                outcome = self._exhausted_outcome
            outcome = self._final_outcome_map.get(outcome, outcome)  # type: ignore[arg-type]
            self._copy_output_keys(self.userdata, parent_ud)
        finally:
            self._is_running = False
        self.call_termination_cbs(self._state_label, outcome)
        return outcome

    def request_preempt(self) -> None:
        self._preempt_requested = True
        if self._is_running and self._state is not None:
            self._state.request_preempt()

    # introspection
    def get_children(self) -> Dict[str, State]:
        return {self._state_label: self._state} if self._state is not None else {}

    def __getitem__(self, key: str) -> State:
        if key != self._state_label or self._state is None:
            log.logerr(f"Attempting to get state '{key}' from Iterator container. The only "
                       f"available state is '{self._state_label}'.")
            raise KeyError(key)
        return self._state

    def get_initial_states(self) -> List[str]:
        return [self._state_label]

    def set_initial_state(self, initial_states: List[str], userdata: Any = None) -> None:
        if len(initial_states) > 1:
            log.logwarn("Attempting to set initial state to include more than one state, but "
                        "Iterator container can only have one initial state.")
        if initial_states and initial_states[0] != self._state_label:
            log.logwarn(f"Attempting to set state '{initial_states[0]}' as initial state in "
                        f"Iterator container. The only available state is '{self._state_label}'.")
            raise KeyError(initial_states[0])
        if userdata is not None:
            self.userdata.update(userdata)

    def get_active_states(self) -> List[str]:
        return [self._state_label] if self._is_running else []

    def get_internal_edges(self) -> List[Tuple[str, str, Any]]:
        edges: List[Tuple[str, str, Any]] = [(o, self._state_label, self._state_label)
                                             for o in self._loop_outcomes]
        for outcome in self._break_outcomes:
            final = self._final_outcome_map.get(outcome, outcome)
            edges.append((outcome, self._state_label, None if final == outcome else final))
        return edges

    def check_consistency(self) -> None:
        pass


__all__ = ["Iterator"]
