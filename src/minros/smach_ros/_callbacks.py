"""The callback conventions the ROS states share: a callback declared with
``smach.cb_interface`` brings its own keys and outcomes, others get the state's."""

from __future__ import annotations

from typing import Any, Callable, Optional, Sequence, Tuple

from minros import smach


def callback_interface(state: smach.State, cb: Optional[Callable[..., Any]], what: str,
                       input_keys: Sequence[str], output_keys: Sequence[str],
                       outcomes: Sequence[str] = (), with_outcomes: bool = False,
                       ) -> Tuple[Sequence[str], Sequence[str]]:
    """Register ``cb``'s interface on ``state``; return the keys it may read and write."""
    if cb is not None and not callable(cb):
        raise smach.InvalidStateError(f"{what} callback object given to "
                                      f"{type(state).__name__} that IS NOT a function object")
    if smach.has_smach_interface(cb):
        inputs, outputs = cb.get_registered_input_keys(), cb.get_registered_output_keys()
        state.register_input_keys(inputs)
        state.register_output_keys(outputs)
        if with_outcomes:
            state.register_outcomes(cb.get_registered_outcomes())
        return inputs, outputs
    return input_keys, output_keys
