"""The parameter server's state (pure): the tree of parameters, who gets which
``paramUpdate`` after a change, and the two together with the subscriptions
(rosmaster.paramserver's shape)."""

from __future__ import annotations

import copy
import threading
from typing import Any, Callable, Dict, List, Tuple

from minros.master.registrations import Caller, RegistrationManager, Registrations
from minros.names import GLOBALNS, SEP, canonicalize_name, is_global, is_private, ns_join


def _key_parts(key: str) -> List[str]:
    return [part for part in key.split(SEP) if part]


def _subscription_key(key: str) -> str:
    """Parameter subscriptions are stored canonical *with* a trailing slash (``/a/b/``)."""
    return key if key == SEP else canonicalize_name(key) + SEP


class ParamTree:
    """Nested-dict parameter storage with rosmaster's semantics (not thread-safe by itself)."""

    def __init__(self) -> None:
        self.root: Dict[str, Any] = {}

    def get(self, key: str) -> Any:
        """Value at the resolved ``key`` (a dict for a namespace); KeyError when unset."""
        value: Any = self.root
        if key != GLOBALNS:
            # The first segment is skipped, as rosmaster does: for a global key it is the empty
            # root; for the odd relative key a non-global caller_id produces it is dropped.
            for part in [p for p in key.split(SEP)[1:] if p]:
                if type(value) is not dict:
                    raise KeyError(key)
                value = value[part]
        return value

    def has(self, key: str) -> bool:
        try:
            self.get(key)
        except KeyError:
            return False
        return True

    def set(self, key: str, value: Any) -> None:
        """Set ``key``; a dict replaces the whole namespace; scalars on the path become namespaces."""
        if key == GLOBALNS:
            if type(value) is not dict:
                raise TypeError("cannot set root of parameter tree to non-dictionary")
            self.root = value
            return
        parts = _key_parts(key)
        node = self.root
        for part in parts[:-1]:
            child = node.get(part)
            if type(child) is not dict:
                # implicit conversion of a value (or nothing) to a namespace
                child = node[part] = {}
            node = child
        node[parts[-1]] = value

    def delete(self, key: str) -> None:
        """Delete ``key``; KeyError when it is not set (or is the root)."""
        if key == GLOBALNS:
            raise KeyError("cannot delete root of parameter tree")
        parts = _key_parts(key)
        node: Any = self.root
        for part in parts[:-1]:
            if type(node) is not dict or part not in node:
                raise KeyError(key)
            node = node[part]
        # Like rosmaster, the last step is plain Python: under a scalar parent this raises
        # TypeError (reported as "invalid arguments"), not KeyError.
        if parts[-1] not in node:
            raise KeyError(key)
        del node[parts[-1]]

    def names(self) -> List[str]:
        """Every leaf key, global; namespaces themselves (and empty dicts) are not listed."""
        out: List[str] = []

        def walk(prefix: str, tree: Dict[str, Any]) -> None:
            for k, v in tree.items():
                if type(v) is dict:
                    walk(ns_join(prefix, k), v)
                else:
                    out.append(ns_join(prefix, k))

        walk(GLOBALNS, self.root)
        return out

    def search(self, ns: str, key: str) -> str | None:
        """searchParam: the caller's private namespace first, then each ancestor namespace.

        Matching is on the first segment of ``key``; the returned full key may not exist yet.
        """
        if not key or is_private(key):
            raise ValueError("invalid key")
        if not is_global(ns):
            raise ValueError("namespace must be global")
        if is_global(key):
            return key if self.has(key) else None
        key_ns = _key_parts(key)[0]
        if self.has(ns_join(ns, key_ns)):
            return ns_join(ns, key)
        namespaces = _key_parts(ns)
        for i in range(1, len(namespaces) + 1):
            if self.has(SEP + SEP.join(namespaces[:-i] + [key_ns])):
                return SEP + SEP.join(namespaces[:-i] + [key])
        return None


def _all_subkeys(param_key: str, value: Dict[str, Any], out: List[str]) -> List[str]:
    for k, v in value.items():
        sub = ns_join(param_key, k) + SEP
        out.append(sub)
        if type(v) is dict:
            _all_subkeys(sub, v, out)
    return out


def compute_param_updates(subscriptions: Registrations, param_key: str, param_value: Any,
                          caller_to_ignore: str | None = None
                          ) -> List[Tuple[List[Caller], str, Any]]:
    """Who gets which ``paramUpdate`` after ``param_key`` changed to ``param_value``.

    * subscribers of ``S/`` with ``K/`` inside ``S/`` get ``(K/, value)`` (the setter excluded);
    * when a dict is set (a delete is the dict ``{}``), subscribers below ``K/`` whose key is absent
      from the new dict get ``(key, {})`` and those present get their own sub-value.
    """
    if not subscriptions:
        return []
    param_key = _subscription_key(param_key)
    all_keys = _all_subkeys(param_key, param_value, []) if type(param_value) is dict else None
    present = set(all_keys) if all_keys is not None else set()
    updates: List[Tuple[List[Caller], str, Any]] = []
    for sub_key in subscriptions.keys():
        ns_key = sub_key if sub_key.endswith(SEP) else sub_key + SEP
        if param_key.startswith(ns_key):
            callers = subscriptions[sub_key]
            if caller_to_ignore is not None:
                callers = [c for c in callers if c[0] != caller_to_ignore]
            updates.append((callers, param_key, param_value))
        elif all_keys is not None and ns_key.startswith(param_key) and sub_key not in present:
            updates.append((subscriptions[sub_key], sub_key, {}))
    if all_keys is not None:
        for key in all_keys:
            if key in subscriptions:
                value: Any = param_value
                for part in _key_parts(key[len(param_key):]):
                    value = value[part]
                updates.append((subscriptions[key], key, value))
    return updates


def _snapshot(value: Any) -> Any:
    """A copy of a namespace (dicts are the only values the tree mutates in place)."""
    return copy.deepcopy(value) if type(value) is dict else value


class ParamDictionary:
    """The parameter server's state: the tree and who subscribed to what (rosmaster's
    ParamDictionary). ``notify_task(updates)`` receives :func:`compute_param_updates`' answer
    after a change, under the lock (so updates reach the queue in the order of the changes)."""

    def __init__(self, reg_manager: RegistrationManager, lock: Any = None) -> None:
        self.lock = lock if lock is not None else threading.RLock()
        self.tree = ParamTree()
        self.reg_manager = reg_manager

    @property
    def parameters(self) -> Dict[str, Any]:
        return self.tree.root

    def get_param_names(self) -> List[str]:
        with self.lock:
            return self.tree.names()

    def search_param(self, ns: str, key: str) -> str | None:
        with self.lock:
            return self.tree.search(ns, key)

    def get_param(self, key: str) -> Any:
        """KeyError when unset."""
        with self.lock:
            return self.tree.get(key)

    def has_param(self, key: str) -> bool:
        with self.lock:
            return self.tree.has(key)

    def set_param(self, key: str, value: Any, notify_task: Callable[[List[Any]], Any] | None = None,
                  caller_id: str | None = None) -> None:
        """Set ``key`` (the setter, ``caller_id``, is not told of its own change)."""
        with self.lock:
            self.tree.set(key, value)
            if notify_task:
                updates = compute_param_updates(self.reg_manager.param_subscribers, key, value,
                                                caller_id)
                if updates:
                    notify_task(updates)

    def delete_param(self, key: str, notify_task: Callable[[List[Any]], Any] | None = None) -> None:
        """KeyError when ``key`` is not set; subscribers learn it as the value ``{}``."""
        with self.lock:
            self.tree.delete(key)
            if notify_task:
                updates = compute_param_updates(self.reg_manager.param_subscribers, key, {})
                if updates:
                    notify_task(updates)

    def subscribe_param(self, key: str, registration_args: Tuple[str, str]) -> Any:
        """Subscribe ``(caller_id, caller_api)`` to ``key``; its value now, ``{}`` if unset."""
        key = _subscription_key(key)
        with self.lock:
            try:
                value = self.tree.get(key)
            except KeyError:
                value = {}
            self.reg_manager.register_param_subscriber(key, *registration_args)
            return value

    def unsubscribe_param(self, key: str, unregistration_args: Tuple[str, str]) -> List[Any]:
        with self.lock:
            return self.reg_manager.unregister_param_subscriber(_subscription_key(key),
                                                               *unregistration_args)
