"""A smach state: declared outcomes and userdata keys, ``execute(ud)``, preemption flags."""

from __future__ import annotations

from typing import Any, Callable, Iterable, Optional, Sequence, Tuple


class State:
    """Base class of smach states.

    A state declares what it may return (outcomes) and which userdata keys it reads and
    writes before it runs; containers check both while they are built and enforce the keys
    at run time (:class:`~minros.smach.user_data.Remapper`).
    """

    def __init__(self, outcomes: Sequence[str] = (), input_keys: Sequence[str] = (),
                 output_keys: Sequence[str] = (), io_keys: Sequence[str] = ()) -> None:
        self._outcomes = set(outcomes)
        self._input_keys = set(input_keys) | set(io_keys)
        self._output_keys = set(output_keys) | set(io_keys)
        self._preempt_requested = False

    def execute(self, ud: Any) -> Optional[str]:
        """Run the state and return one of its outcomes (subclasses implement it)."""
        raise NotImplementedError(f"{type(self).__name__} does not implement execute(ud)")

    # the interface a container reads
    def register_outcomes(self, new_outcomes: Iterable[str]) -> None:
        self._outcomes |= set(new_outcomes)

    def get_registered_outcomes(self) -> Tuple[str, ...]:
        return tuple(self._outcomes)

    def register_io_keys(self, keys: Iterable[str]) -> None:
        keys = set(keys)
        self._input_keys |= keys
        self._output_keys |= keys

    def register_input_keys(self, keys: Iterable[str]) -> None:
        self._input_keys |= set(keys)

    def get_registered_input_keys(self) -> Tuple[str, ...]:
        return tuple(self._input_keys)

    def register_output_keys(self, keys: Iterable[str]) -> None:
        self._output_keys |= set(keys)

    def get_registered_output_keys(self) -> Tuple[str, ...]:
        return tuple(self._output_keys)

    # preemption: a flag the running state polls (containers set it on their children)
    def request_preempt(self) -> None:
        self._preempt_requested = True

    def service_preempt(self) -> None:
        """The state acknowledges the preempt it acted on."""
        self._preempt_requested = False

    def recall_preempt(self) -> None:
        """The container withdraws a preempt the state never acted on."""
        self._preempt_requested = False

    def preempt_requested(self) -> bool:
        return self._preempt_requested


def has_smach_interface(obj: Any) -> bool:
    """Whether ``obj`` declares outcomes and keys (a state, or a callback wrapped by
    :func:`cb_interface`)."""
    return all(hasattr(obj, name) for name in (
        "get_registered_input_keys", "get_registered_output_keys", "get_registered_outcomes"))


class CBInterface:
    """A callback with the outcomes and userdata keys it adds to the state that calls it."""

    def __init__(self, cb: Callable[..., Any], outcomes: Optional[Sequence[str]] = None,
                 input_keys: Optional[Sequence[str]] = None,
                 output_keys: Optional[Sequence[str]] = None,
                 io_keys: Optional[Sequence[str]] = None) -> None:
        self._cb = cb
        self._outcomes = list(outcomes or [])
        self._input_keys = set(input_keys or []) | set(io_keys or [])
        self._output_keys = set(output_keys or []) | set(io_keys or [])
        self.__name__ = getattr(cb, "__name__", type(self).__name__)
        self.__doc__ = getattr(cb, "__doc__", None)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self._cb(*args, **kwargs)

    def get_registered_input_keys(self) -> Tuple[str, ...]:
        return tuple(self._input_keys)

    def get_registered_output_keys(self) -> Tuple[str, ...]:
        return tuple(self._output_keys)

    def get_registered_outcomes(self) -> Tuple[str, ...]:
        return tuple(self._outcomes)


class cb_interface:  # noqa: N801 - smach's name
    """Decorator: ``@smach.cb_interface(outcomes=[...], input_keys=[...], output_keys=[...])``."""

    def __init__(self, outcomes: Optional[Sequence[str]] = None,
                 input_keys: Optional[Sequence[str]] = None,
                 output_keys: Optional[Sequence[str]] = None,
                 io_keys: Optional[Sequence[str]] = None) -> None:
        self._args = (outcomes, input_keys, output_keys, io_keys)

    def __call__(self, cb: Callable[..., Any]) -> CBInterface:
        return CBInterface(cb, *self._args)


class CBState(State):
    """A state made of one function ``cb(ud, *cb_args, **cb_kwargs) -> outcome``; a callback
    decorated with :func:`cb_interface` brings its outcomes and keys along."""

    def __init__(self, cb: Callable[..., Any], cb_args: Sequence[Any] = (),
                 cb_kwargs: Optional[dict] = None, outcomes: Sequence[str] = (),
                 input_keys: Sequence[str] = (), output_keys: Sequence[str] = (),
                 io_keys: Sequence[str] = ()) -> None:
        super().__init__(outcomes, input_keys, output_keys, io_keys)
        self._cb = cb
        self._cb_args = list(cb_args)
        self._cb_kwargs = dict(cb_kwargs or {})
        if has_smach_interface(cb):
            self.register_input_keys(cb.get_registered_input_keys())
            self.register_output_keys(cb.get_registered_output_keys())
            self.register_outcomes(cb.get_registered_outcomes())

    def execute(self, ud: Any) -> Optional[str]:
        return self._cb(ud, *self._cb_args, **self._cb_kwargs)


__all__ = ["State", "CBState"]
