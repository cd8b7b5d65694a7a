"""StateMachine: one active state at a time, its outcome picks the next state or ends the
machine; Sequence: a StateMachine whose states are chained in the order they are added."""

from __future__ import annotations

import threading
import traceback
from typing import Any, Dict, List, Mapping, Optional, Tuple
from typing import Sequence as Seq

from minros.smach import log
from minros.smach.container import Container
from minros.smach.exceptions import InvalidStateError, InvalidTransitionError, InvalidUserCodeError
from minros.smach.state import State
from minros.smach.user_data import Remapper


class StateMachine(Container):
    """A finite state machine container.

    States are added as (label, state, transitions, remapping[, constants]); a transition maps
    an outcome of the state to another state's label, to an outcome of the machine, or to
    None (the outcome then ends the machine under its own name).
    """

    def __init__(self, outcomes: Seq[str], input_keys: Seq[str] = (),
                 output_keys: Seq[str] = ()) -> None:
        super().__init__(outcomes, input_keys, output_keys)
        # Held while the machine decides what runs next, released while a state executes:
        # request_preempt() must see a consistent current state.
        self._state_transitioning_lock = threading.Lock()
        self._is_running = False
        self._initial_state_label: Optional[str] = None
        self._current_label: Optional[str] = None
        self._current_state: Optional[State] = None
        self._current_transitions: Optional[Dict[str, Any]] = None
        self._preempted_label: Optional[str] = None
        self._preempted_state: Optional[State] = None
        self._states: Dict[str, State] = {}
        self._transitions: Dict[str, Dict[str, Any]] = {}
        self._remappings: Dict[str, Dict[str, str]] = {}
        self._constants: Dict[str, Dict[str, Any]] = {}
        self._last_added_label: Optional[str] = None
        self._connector_outcomes: List[str] = []

    def __getstate__(self) -> Dict[str, Any]:
        return {k: v for k, v in self.__dict__.items() if k != "_state_transitioning_lock"}

    def __setstate__(self, state: Dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._state_transitioning_lock = threading.Lock()

    # construction
    @staticmethod
    def add(label: str, state: State, transitions: Optional[Mapping[str, Any]] = None,
            remapping: Optional[Mapping[str, str]] = None,
            constants: Optional[Mapping[str, Any]] = None) -> State:
        """Add ``state`` under ``label`` to the open state machine (the first one added is
        the initial state); ``constants`` are written into the machine's userdata each time
        the state is entered."""
        self = StateMachine._currently_opened_container()
        transitions = dict(transitions or {})
        self.check_state_spec(label, state, transitions)
        if label in self._states:
            raise InvalidStateError(
                f'Attempting to add state with label "{label}" to state machine, but this '
                "label is already being used.")
        if self._initial_state_label is None:
            self._initial_state_label = label
        for outcome in state.get_registered_outcomes():
            transitions.setdefault(outcome, None)
        self._states[label] = state
        self._transitions[label] = transitions
        self._remappings[label] = dict(remapping or {})
        self._constants[label] = dict(constants or {})
        if self._connector_outcomes and self._last_added_label is not None:
            for outcome in self._connector_outcomes:
                self._transitions[self._last_added_label][outcome] = label
            self._connector_outcomes = []
            self._last_added_label = None
        return state

    @staticmethod
    def add_auto(label: str, state: State, connector_outcomes: Seq[str],
                 transitions: Optional[Mapping[str, Any]] = None,
                 remapping: Optional[Mapping[str, str]] = None,
                 constants: Optional[Mapping[str, Any]] = None) -> State:
        """Add a state whose ``connector_outcomes`` lead to the next state added."""
        self = StateMachine._currently_opened_container()
        added = StateMachine.add(label, state, transitions, remapping, constants)
        registered = state.get_registered_outcomes()
        if not all(o in registered for o in connector_outcomes):
            raise InvalidStateError(
                f"Attempting to auto-connect states with outcomes {list(connector_outcomes)}, "
                f"but state '{label}' only has registered outcomes: {registered}")
        self._last_added_label = label
        self._connector_outcomes = list(connector_outcomes)
        return added

    def check_state_spec(self, label: str, state: State, transitions: Mapping[str, Any]) -> None:
        registered = state.get_registered_outcomes()
        for outcome in transitions:
            if outcome not in registered:
                raise InvalidTransitionError(
                    f"Specified outcome '{outcome}' on state '{label}', which only has "
                    f"available registered outcomes: {registered}")

    def check_consistency(self) -> None:
        """Every transition leads to a state or an outcome of the machine; raises
        InvalidTransitionError listing every problem."""
        available = set(self._states) | set(self.get_registered_outcomes())
        own_outcomes = set(self.get_registered_outcomes())
        errors = []
        if self._initial_state_label is None:
            errors.append("No initial state set.")
        elif self._initial_state_label not in self._states:
            errors.append(f"Initial state label: '{self._initial_state_label}' is not in the "
                          "state machine.")
        for label, transitions in self._transitions.items():
            targets = {t for t in transitions.values() if t}
            unknown = targets - available
            if unknown:
                errors.append(f"State '{label}' references unknown states: {sorted(unknown)}")
            ending = {o for o, t in transitions.items() if not t}
            unregistered = ending - own_outcomes
            if unregistered:
                errors.append(f"State '{label}' references unregistered outcomes: "
                              f"{sorted(unregistered)}")
        if errors:
            raise InvalidTransitionError(
                "State machine failed consistency check: " + "".join("\n\t" + e for e in errors)
                + f"\n\n\tAvailable states: {sorted(available)}")

    # running
    def _set_current_state(self, label: Optional[str]) -> None:
        self._current_label = label
        self._current_state = self._states[label] if label is not None else None
        self._current_transitions = self._transitions[label] if label is not None else None

    def _preempt_current_state(self) -> None:
        """Pass the preempt on to the current state (recalling it from an earlier state that
        never serviced it)."""
        if self._preempted_state is self._current_state:
            return
        if self._preempted_state is not None:
            self._preempted_state.recall_preempt()
        self._preempted_state = self._current_state
        self._preempted_label = self._current_label
        try:
            self._preempted_state.request_preempt()  # type: ignore[union-attr]
        except Exception:  # noqa: BLE001 - user code
            log.logerr(f"Failed to preempt contained state '{self._preempted_label}': "
                       f"{traceback.format_exc()}")

    def _update_once(self) -> Optional[str]:
        """Run the current state; move to the next one, or return the machine's outcome."""
        label = self._current_label
        state = self._current_state
        if label not in self._states or state is None:
            raise InvalidStateError(f"State '{label}' does not exist. Available states are: "
                                    f"{list(self._states)}")
        if self.preempt_requested():
            log.loginfo("Preempt requested on state machine before executing the next state.")
            if self._preempted_state is None:
                self._preempt_current_state()
            elif self._preempted_state.preempt_requested():
                log.loginfo(f"Last state '{self._preempted_label}' did not service preempt. "
                            f"Preempting next state '{label}' before executing...")
                self._preempt_current_state()
            else:  # the preempted state serviced it: the machine's preempt is done
                self._preempt_requested = False
                self._preempted_state = None
        for key, value in self._constants[label].items():
            self.userdata[key] = value
        self._state_transitioning_lock.release()
        try:
            outcome = state.execute(Remapper(self.userdata, state.get_registered_input_keys(),
                                             state.get_registered_output_keys(),
                                             self._remappings[label]))
        except InvalidUserCodeError:
            log.logerr(f"State '{label}' failed to execute.")
            raise
        except Exception:  # noqa: BLE001 - user code, reported with its traceback
            raise InvalidUserCodeError(f"Could not execute state '{label}' of type '{state}': "
                                       + traceback.format_exc()) from None
        finally:
            self._state_transitioning_lock.acquire()
        if outcome not in state.get_registered_outcomes():
            raise InvalidTransitionError(
                f"Attempted to return outcome '{outcome}' from state '{label}' of type "
                f"'{state}' which only has registered outcomes: {state.get_registered_outcomes()}")
        transitions = self._current_transitions or {}
        if outcome not in transitions:
            raise InvalidTransitionError(
                f"Outcome '{outcome}' of state '{label}' is not bound to any transition target. "
                f"Bound transitions include: {transitions}")
        target = transitions[outcome]
        if target in self._states:
            self._set_current_state(target)
            log.loginfo(f"State machine transitioning '{label}':'{outcome}'-->'{target}'")
            self.call_transition_cbs()
            return None
        if self._preempt_requested and self._preempted_state is not None \
                and not state.preempt_requested():
            self.service_preempt()
        if target not in self.get_registered_outcomes():
            target = outcome  # None or '' ends the machine with the state's own outcome
        if target not in self.get_registered_outcomes():
            raise InvalidTransitionError(
                f"Outcome '{outcome}' of state '{label}' with transition target '{target}' is "
                "neither a registered state nor a registered container outcome.")
        self._set_current_state(None)
        log.loginfo(f"State machine terminating '{label}':'{outcome}':'{target}'")
        self.call_termination_cbs([label], target)
        return target

    def execute(self, parent_ud: Any = None) -> Optional[str]:
        """Run from the initial state until an outcome of the machine (None when the
        machine is inconsistent or smach is shut down)."""
        with self._state_transitioning_lock:
            try:
                self.check_consistency()
            except (InvalidStateError, InvalidTransitionError):
                log.logerr("Container consistency check failed.")
                return None
            self._is_running = True
            self._preempted_label = None
            self._preempted_state = None
            self._set_current_state(self._initial_state_label)
            self._copy_input_keys(parent_ud, self.userdata)
            log.loginfo(f"State machine starting in initial state '{self._current_label}' with "
                        f"userdata: \n\t{self.userdata.keys()}")
            self.call_start_cbs()
            outcome = None
            try:
                while outcome is None and self._is_running and not log.is_shutdown():
                    outcome = self._update_once()
                self._copy_output_keys(self.userdata, parent_ud)
            finally:
                self._is_running = False
        return outcome

    def request_preempt(self) -> None:
        with self._state_transitioning_lock:
            self._preempt_requested = True
            if self._current_state is not None:
                self._preempt_current_state()

    def is_running(self) -> bool:
        return self._is_running

    # introspection
    def get_children(self) -> Dict[str, State]:
        return self._states

    def __getitem__(self, key: str) -> State:
        if key not in self._states:
            log.logerr(f"Attempting to get state '{key}' from StateMachine container. The only "
                       f"available states are: {list(self._states)}")
            raise KeyError(key)
        return self._states[key]

    def set_initial_state(self, initial_states: List[str], userdata: Any = None) -> None:
        if len(initial_states) > 1:
            log.logwarn("Attempting to set initial state to include more than one state, but "
                        "the StateMachine container can only have one initial state. Taking "
                        "the first one.")
        if initial_states:
            self._initial_state_label = initial_states[0]
        if userdata is not None:
            self.userdata.update(userdata)

    def get_active_states(self) -> List[str]:
        return [str(self._current_label)]

    def get_initial_states(self) -> List[str]:
        return [str(self._initial_state_label)]

    def get_internal_edges(self) -> List[Tuple[str, str, Any]]:
        return [(outcome, label, target) for label, transitions in self._transitions.items()
                for outcome, target in transitions.items()]


class Sequence(StateMachine):
    """States run in the order added: each one's ``connector_outcome`` leads to the next
    (unless its transitions say otherwise)."""

    def __init__(self, outcomes: Seq[str], connector_outcome: str, input_keys: Seq[str] = (),
                 output_keys: Seq[str] = ()) -> None:
        super().__init__(outcomes, input_keys, output_keys)
        self._last_added_seq_label: Optional[str] = None
        self._connector_outcome = connector_outcome

    @staticmethod
    def add(label: str, state: State, transitions: Optional[Mapping[str, Any]] = None,
            remapping: Optional[Mapping[str, str]] = None,
            constants: Optional[Mapping[str, Any]] = None) -> State:
        self = Sequence._currently_opened_container()
        last = self._last_added_seq_label
        if last is not None and self._transitions[last].get(self._connector_outcome) is None:
            self._transitions[last][self._connector_outcome] = label
        self._last_added_seq_label = label
        return StateMachine.add(label, state, transitions, remapping, constants)


__all__ = ["StateMachine", "Sequence"]
