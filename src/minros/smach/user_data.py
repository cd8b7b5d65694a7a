"""smach's userdata: a thread-safe key/value store, the remapping view each state sees,
and the read-only wrapper for keys a state may read but not write."""

from __future__ import annotations

import copy
import threading
from typing import Any, Iterable, List, Mapping

from minros.smach import log
from minros.smach.exceptions import InvalidUserCodeError


class MissingKey(KeyError, AttributeError):
    """A userdata key that is not there: a KeyError as in ROS's smach, and an AttributeError
    too, so ``hasattr(ud, key)`` and ``getattr(ud, key, default)`` work."""


class UserData:
    """The data a container's states share, by key (``ud.key`` or ``ud['key']``)."""

    def __init__(self) -> None:
        object.__setattr__(self, "_data", {})
        object.__setattr__(self, "_lock", threading.RLock())

    def update(self, other_userdata: UserData) -> None:
        """Copy every key of ``other_userdata`` in, overwriting."""
        with self._lock:
            self._data.update(other_userdata._data)

    def extract(self, keys: Iterable[str], remapping: Mapping[str, str]) -> UserData:
        """A new UserData with ``keys`` (copied), named as the remapping's local side."""
        reverse = {parent: local for local, parent in remapping.items()}
        if len(reverse) != len(remapping):
            log.logerr(f"SMACH userdata remapping is not one-to-one: {dict(remapping)}")
        out = UserData()
        for key in keys:
            out[reverse.get(key, key)] = copy.copy(self[key])
        return out

    def merge(self, ud: UserData, keys: Iterable[str], remapping: Mapping[str, str]) -> None:
        """Copy ``keys`` of ``ud`` in, each under its remapped name."""
        for key in keys:
            self[remapping.get(key, key)] = copy.copy(ud[key])

    def keys(self) -> List[str]:
        with self._lock:
            return list(self._data)

    def __contains__(self, key: object) -> bool:
        return key in self._data

    def __getitem__(self, key: str) -> Any:
        with self._lock:
            try:
                return self._data[key]
            except KeyError:
                available = list(self._data)
        log.logerr(f"Userdata key '{key}' not available. Available keys are: {available}")
        raise MissingKey(key)

    def __setitem__(self, key: str, value: Any) -> None:
        with self._lock:
            self._data[key] = value

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        return self[name]

    def __setattr__(self, name: str, value: Any) -> None:
        if name.startswith("_"):
            object.__setattr__(self, name, value)
        else:
            self[name] = value

    def __repr__(self) -> str:
        return f"UserData({self._data!r})"


def get_const(obj: Any) -> Any:
    """``obj`` wrapped read-only when it has attributes of its own (plain values, tuples and
    slotted ROS messages pass as they are)."""
    return Const(obj) if hasattr(obj, "__dict__") else obj


class Const:
    """A read-only view of an object: setting or deleting an attribute raises TypeError."""

    def __init__(self, obj: Any) -> None:
        object.__setattr__(self, "_obj", obj)

    def __getattr__(self, name: str) -> Any:
        return get_const(getattr(self._obj, name))

    def __getitem__(self, key: Any) -> Any:
        return get_const(self._obj[key])

    def __setattr__(self, name: str, value: Any) -> None:
        log.logerr(f"Attempting to set '{name}' but this member is read-only.")
        raise TypeError(f"'{name}' is read-only: declare the key as an output key to write it")

    def __delattr__(self, name: str) -> None:
        log.logerr(f"Attempting to delete '{name}' but this member is read-only.")
        raise TypeError(f"'{name}' is read-only: declare the key as an output key to change it")


class Remapper:
    """The userdata a state sees: only its declared keys, renamed through ``remapping``
    (local name -> container key); input-only keys come back read-only."""

    def __init__(self, ud: Any, input_keys: Iterable[str] = (), output_keys: Iterable[str] = (),
                 remapping: Mapping[str, str] | None = None) -> None:
        object.__setattr__(self, "_ud", ud)
        object.__setattr__(self, "_input", set(input_keys))
        object.__setattr__(self, "_output", set(output_keys))
        object.__setattr__(self, "_map", dict(remapping or {}))

    def _remap(self, key: str) -> str:
        return self._map.get(key, key)

    def update(self, other_userdata: Any) -> None:
        self._ud.update(other_userdata)

    def keys(self) -> List[str]:
        return [key for key in self._input if self._remap(key) in self._ud]

    def __contains__(self, key: object) -> bool:
        return key in self._input and self._remap(key) in self._ud  # type: ignore[arg-type]

    def _read(self, key: str) -> Any:
        if key not in self._input:
            raise InvalidUserCodeError(
                f"Reading from SMACH userdata key '{key}' but the only keys that were declared "
                f"as input to this state were: {sorted(self._input)}. This key needs to be "
                "declared as input to this state. ")
        value = self._ud[self._remap(key)]
        return value if key in self._output else get_const(value)

    def _write(self, key: str, value: Any) -> None:
        if key not in self._output:
            log.logerr(f"Writing to SMACH userdata key '{key}' but the only keys that were "
                       f"declared as output from this state were: {sorted(self._output)}.")
            return
        self._ud[self._remap(key)] = value

    def __getitem__(self, key: str) -> Any:
        return self._read(key)

    def __setitem__(self, key: str, value: Any) -> None:
        self._write(key, value)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        return self._read(name)

    def __setattr__(self, name: str, value: Any) -> None:
        if name.startswith("_"):
            object.__setattr__(self, name, value)
        else:
            self._write(name, value)


def copy_keys(source: Any, target: Any, keys: Iterable[str], what: str) -> None:
    """``target[k] = source[k]`` for each key, warning about missing ones (containers copy
    their declared keys in from the parent and out to it this way)."""
    if source is None or target is None:
        return
    for key in keys:
        if key in source:
            target[key] = source[key]
        else:
            log.logwarn(f"Attempting to copy {what} key '{key}', but this key does not exist.")


__all__: List[str] = ["UserData", "Remapper", "Const", "get_const"]
