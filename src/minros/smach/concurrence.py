"""Concurrence: every child runs at once, each in its own thread; the container ends when
all have ended (a child termination callback may preempt the rest first) and its outcome
comes from the outcome callback, the outcome map, or the default outcome."""

from __future__ import annotations

import threading
import traceback
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple

from minros.smach import log
from minros.smach.container import Container
from minros.smach.exceptions import InvalidStateError, InvalidTransitionError, InvalidUserCodeError
from minros.smach.state import State
from minros.smach.user_data import Remapper


class Concurrence(Container):
    """Split-join concurrency.

    ``outcome_map`` maps a container outcome to the child outcomes it requires
    (``{'succeeded': {'FOO': 'succeeded', 'BAR': 'done'}}``); when several are satisfied the
    one with most requirements wins. ``outcome_cb(child_outcomes)`` may return the outcome
    instead. ``child_termination_cb(child_outcomes)`` runs each time a child ends: True
    preempts the children still running (so the first to end can end the container).
    """

    def __init__(self, outcomes: Sequence[str], default_outcome: str,
                 input_keys: Sequence[str] = (), output_keys: Sequence[str] = (),
                 outcome_map: Optional[Mapping[str, Mapping[str, str]]] = None,
                 outcome_cb: Optional[Callable[[Dict[str, Optional[str]]], Any]] = None,
                 child_termination_cb: Optional[Callable[[Dict[str, Optional[str]]], Any]] = None
                 ) -> None:
        super().__init__(outcomes, input_keys, output_keys)
        outcome_map = dict(outcome_map or {})
        if not (default_outcome or outcome_map or outcome_cb):
            raise InvalidStateError("Concurrence requires an outcome policy")
        errors = []
        if not isinstance(default_outcome, str):
            errors.append(f"Default outcome '{default_outcome}' does not appear to be a string.")
        if default_outcome not in outcomes:
            errors.append(f"Default outcome '{default_outcome}' is unregistered.")
        errors += [f"Unregistered outcome '{o}' in and_outcome_map." for o in outcome_map
                   if o not in outcomes]
        if outcome_cb is not None and not callable(outcome_cb):
            errors.append(f"Outcome callback '{outcome_cb}' is not callable.")
        if child_termination_cb is not None and not callable(child_termination_cb):
            errors.append(f"Child termination callback '{child_termination_cb}' is not callable.")
        if errors:
            raise InvalidStateError("Errors specifying outcome policy of concurrence: "
                                    + "".join("\n\t" + e for e in errors))
        self._default_outcome = default_outcome
        self._outcome_map = outcome_map
        self._outcome_cb = outcome_cb
        self._child_termination_cb = child_termination_cb
        self._states: Dict[str, State] = {}
        self._remappings: Dict[str, Dict[str, str]] = {}
        self._threads: Dict[str, threading.Thread] = {}
        self._child_outcomes: Dict[str, Optional[str]] = {}
        self._child_errors: List[str] = []
        # notified when a child ends (or fails) and when the container is preempted
        self._done_cond = threading.Condition()

    @staticmethod
    def add(label: str, state: State, remapping: Optional[Mapping[str, str]] = None) -> State:
        self = Concurrence._currently_opened_container()
        self._states[label] = state
        self._remappings[label] = dict(remapping or {})
        return state

    def _finished(self) -> bool:
        return all(o is not None for o in self._child_outcomes.values())

    def execute(self, parent_ud: Any = None) -> Optional[str]:
        if not self._states:
            raise InvalidStateError("No states was added to concurrence")
        self._child_errors = []
        self._copy_input_keys(parent_ud, self.userdata)
        log.loginfo(f"Concurrence starting with userdata: \n\t{self.userdata.keys()}")
        self.call_start_cbs()
        with self._done_cond:
            self._child_outcomes = {label: None for label in self._states}
            self._stop = False
            self._threads = {label: threading.Thread(name=f"concurrent_split:{label}",
                                                     target=self._state_runner, args=(label,),
                                                     daemon=True)
                             for label in self._states}
            for thread in self._threads.values():
                thread.start()
            # wait for every child, a child termination callback, an error or a preempt
            while not (self._finished() or self._stop or self._child_errors
                       or self.preempt_requested()):
                self._done_cond.wait()
        log.logdebug("SMACH Concurrence preempting running states.")
        for label, state in self._states.items():
            if self._child_outcomes.get(label) is None:
                state.request_preempt()
        for thread in self._threads.values():
            while thread.is_alive() and not log.is_shutdown():
                thread.join(0.1)
        self._threads = {}
        if self._child_errors:
            errors, self._child_errors = self._child_errors, []
            raise InvalidStateError("A concurrent state raised an exception during execution.\n"
                                    + "\n".join(errors))
        if self.preempt_requested():
            serviced = True
            for label, state in self._states.items():
                if state.preempt_requested():
                    serviced = False
                    log.logwarn(f"State '{label}' in concurrence did not service preempt.")
                    state.recall_preempt()
            if serviced:
                log.loginfo("Concurrence serviced preempt.")
                self.service_preempt()
                return self._terminate("preempted", parent_ud)
        log.loginfo(f"Concurrent Outcomes: {self._child_outcomes}")
        return self._terminate(self._decide(), parent_ud)

    def _decide(self) -> str:
        outcome = self._default_outcome
        best = 0
        for container_outcome, required in self._outcome_map.items():
            if all(self._child_outcomes.get(label) == o for label, o in required.items()) \
                    and len(required) > best:
                outcome, best = container_outcome, len(required)
        if self._outcome_cb is not None:
            try:
                chosen = self._outcome_cb(dict(self._child_outcomes))
            except Exception:  # noqa: BLE001 - user code
                raise InvalidUserCodeError(f"Could not execute outcome callback "
                                           f"'{self._outcome_cb}': " + traceback.format_exc()) from None
            if isinstance(chosen, str) and chosen:
                outcome = chosen
            elif chosen:
                log.logerr(f"Outcome callback returned a non-string '{chosen}', using default "
                           f"outcome '{self._default_outcome}'")
            else:
                log.logwarn(f"Outcome callback returned None, using outcome '{outcome}'")
        return outcome

    def _terminate(self, outcome: str, parent_ud: Any) -> str:
        self._child_outcomes = {}
        self.call_termination_cbs(list(self._states), outcome)
        self._copy_output_keys(self.userdata, parent_ud)
        return outcome

    def _state_runner(self, label: str) -> None:
        state = self._states[label]
        self.call_transition_cbs()
        try:
            outcome = state.execute(Remapper(self.userdata, state.get_registered_input_keys(),
                                             state.get_registered_output_keys(),
                                             self._remappings[label]))
            if outcome is None:
                raise InvalidStateError(f"Concurrent state '{label}' returned no outcome on "
                                        "termination.")
        except Exception:  # noqa: BLE001 - reported by execute() in the container's thread
            message = f"Could not execute child state '{label}': {traceback.format_exc()}"
            log.logerr(message)
            with self._done_cond:
                self._child_errors.append(message)
                self._done_cond.notify_all()
            return
        log.loginfo(f"Concurrent state '{label}' returned outcome '{outcome}' on termination.")
        with self._done_cond:
            self._child_outcomes[label] = outcome
            self.call_transition_cbs()
            if self._child_termination_cb is not None:
                try:
                    if self._child_termination_cb(dict(self._child_outcomes)):
                        self._stop = True
                except Exception:  # noqa: BLE001 - user code
                    self._child_errors.append("Could not execute child termination callback: "
                                              + traceback.format_exc())
            self._done_cond.notify_all()

    def request_preempt(self) -> None:
        """Preempt the container: every child still running is asked to stop."""
        super().request_preempt()
        with self._done_cond:
            self._done_cond.notify_all()

    # introspection
    def get_children(self) -> Dict[str, State]:
        return self._states

    def __getitem__(self, key: str) -> State:
        return self._states[key]

    def get_initial_states(self) -> List[str]:
        return list(self._states)

    def set_initial_state(self, initial_states: List[str], userdata: Any = None) -> None:
        if initial_states and len(initial_states) < len(self._states):
            log.logwarn("Attempting to set initial states in Concurrence container, but "
                        "Concurrence children are always all executed initially, ignoring call.")
        if userdata is not None:
            self.userdata.update(userdata)

    def get_active_states(self) -> List[str]:
        return [label for label, outcome in self._child_outcomes.items() if outcome is None]

    def get_internal_edges(self) -> List[Tuple[str, str, Any]]:
        return [(child_outcome, label, container_outcome)
                for container_outcome, required in self._outcome_map.items()
                for label, child_outcome in required.items()]

    def check_consistency(self) -> None:
        for required in self._outcome_map.values():
            for label, outcome in required.items():
                if label not in self._states:
                    raise InvalidTransitionError(
                        f"Outcome map in SMACH Concurrence references state '{label}', but the "
                        f"concurrence only has states {sorted(self._states)}")
                if outcome not in self._states[label].get_registered_outcomes():
                    raise InvalidTransitionError(
                        "Outcome map in SMACH Concurrence references a state outcome that does "
                        f"not exist. Requested state outcome: '{outcome}', but state '{label}' "
                        f"only has outcomes {self._states[label].get_registered_outcomes()}")


__all__ = ["Concurrence"]
