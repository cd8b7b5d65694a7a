"""The parameter server from a node: rospy's get/set/has/delete/search_param and friends.

Names resolve like every other graph name (caller's namespace, ``~`` = the node's private
namespace, remappings applied to the resolved name). ``get_param_cached`` subscribes to the key
on the master (``subscribeParam``) and keeps a local tree fresh from the master's
``paramUpdate`` calls; plain ``get_param`` answers from that tree too once a key is cached, and
``set_param`` updates it, as rospy does.

The first section names the node context shared with ``minros.client.services`` (the node runtime's
own functions): both work before ``init_node``.
"""

from __future__ import annotations

import threading
import warnings
from typing import Any, Dict, List

from minros import names, node
from minros.exceptions import ROSException

__all__ = [
    "delete_param",
    "get_param",
    "get_param_cached",
    "get_param_names",
    "has_param",
    "search_param",
    "set_param",
]

# --------------------------------------------------------------------------- node context
# The node runtime answers these before init_node too (caller id ``/unnamed`` in the namespace,
# master from ``__master:=`` or ROS_MASTER_URI), so this module and minros.client.services use it as is.

_caller_id = node.get_caller_id
_node_uri = node.get_node_uri
_mappings = node.get_mappings
_resolve = node.resolve_name
_is_shutdown = node.is_shutdown
_wait_for_shutdown = node.wait_for_shutdown
_call_master = node.master_call


# --------------------------------------------------------------------------- the cache

class ParamCache:
    """Local copy of the parameter keys this node subscribed to (a nested dict tree)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.tree: Dict[str, Any] | None = None
        #: subscribed keys the master answered "not set" for: known unset until a paramUpdate
        #: or set_param says otherwise (rospy asks the master again on every call instead)
        self.unset: set = set()

    @staticmethod
    def _parts(key: str) -> List[str]:
        return [p for p in key.split(names.SEP) if p]

    def set(self, key: str, value: Any) -> None:
        """Store ``value`` at ``key`` (the prerequisite of ``update``)."""
        with self.lock:
            parts = self._parts(key)
            if not parts:
                if not isinstance(value, dict):
                    raise TypeError("cannot set root of parameter tree to non-dictionary")
                self.tree = value
                return
            if self.tree is None:
                self.tree = {}
            d = self.tree
            for part in parts[:-1]:
                child = d.get(part)
                if not isinstance(child, dict):
                    child = d[part] = {}
                d = child
            d[parts[-1]] = value

    def mark_unset(self, key: str) -> None:
        """The master says ``key`` is not set, and will tell us (paramUpdate) when it is."""
        with self.lock:
            self.unset.add(tuple(self._parts(key)))

    def is_unset(self, key: str) -> bool:
        return tuple(self._parts(key)) in self.unset

    def update(self, key: str, value: Any) -> None:
        """Replace the value at an already cached ``key``; KeyError if it is not cached."""
        # the master names a key with or without its trailing '/': compare the parts
        if self.is_unset(key) and not (isinstance(value, dict) and not value):
            with self.lock:
                self.unset.discard(tuple(self._parts(key)))
            self.set(key, value)
            return
        with self.lock:
            parts = self._parts(key)
            d = self.tree
            if d is None or not parts:
                raise KeyError(key)
            for part in parts[:-1]:
                d = d.get(part) if isinstance(d, dict) else None
                if d is None:
                    raise KeyError(key)
            if not isinstance(d, dict) or parts[-1] not in d:
                raise KeyError(key)
            d[parts[-1]] = value

    def get(self, key: str) -> Any:
        """The cached value; KeyError if absent or an empty namespace (= unset on the master)."""
        with self.lock:
            value: Any = self.tree
            if value is None:
                raise KeyError(key)
            for part in self._parts(key):
                if not isinstance(value, dict) or part not in value:
                    raise KeyError(key)
                value = value[part]
            if isinstance(value, dict) and not value:
                raise KeyError(key)
            return value

    def delete(self, key: str) -> None:
        """Forget ``key``; KeyError if it is not cached (rospy.impl.paramserver's contract)."""
        with self.lock:
            parts = self._parts(key)
            d = self.tree
            if d is None or not parts:
                raise KeyError(key)
            for part in parts[:-1]:
                d = d.get(part) if isinstance(d, dict) else None
                if d is None:
                    raise KeyError(key)
            if not isinstance(d, dict) or parts[-1] not in d:
                raise KeyError(key)
            del d[parts[-1]]

    def clear(self) -> None:
        with self.lock:
            self.tree = None
            self.unset.clear()


_cache = ParamCache()
_update_handler_installed = False
_install_lock = threading.Lock()


def _on_param_update(key: str, value: Any) -> bool:
    """The slave's ``paramUpdate``: refresh a cached key; False if the key is not cached."""
    try:
        _cache.update(key, value)
    except KeyError:
        return False
    return True


def _install_update_handler() -> None:
    global _update_handler_installed
    with _install_lock:
        if _update_handler_installed:
            return
        node.add_param_update_handler(_on_param_update)
        _update_handler_installed = True


# --------------------------------------------------------------------------- public API

class _Unspecified:
    def __repr__(self) -> str:
        return "<unspecified>"


_unspecified: Any = _Unspecified()


def get_param(param_name: str, default: Any = _unspecified) -> Any:
    """The value of ``param_name``; ``default`` if unset, else KeyError(param_name)."""
    resolved = _resolve(param_name)
    try:
        return _cache.get(resolved)
    except KeyError:
        pass
    code, _msg, value = _call_master("getParam", resolved)
    if code != 1:
        if default is not _unspecified:
            return default
        raise KeyError(param_name)
    return value


def get_param_cached(param_name: str, default: Any = _unspecified) -> Any:
    """Like ``get_param``, but subscribes to the key and answers locally from then on."""
    resolved = _resolve(param_name)
    try:
        return _cache.get(resolved)
    except KeyError:
        pass
    if _cache.is_unset(resolved):  # subscribed, and not set since: no need to ask again
        if default is not _unspecified:
            return default
        raise KeyError(param_name)
    if not _node_uri():
        # no node to receive paramUpdate: a plain lookup is the best we can do
        return get_param(param_name, default)
    _install_update_handler()
    value = node.subscribe_param(resolved)
    if isinstance(value, dict) and not value:  # subscribeParam answers {} for an unset key
        _cache.mark_unset(resolved)
        if default is not _unspecified:
            return default
        raise KeyError(param_name)
    _cache.set(resolved, value)
    return value


def set_param(param_name: str, param_value: Any) -> None:
    """Set ``param_name``; a dict replaces the whole namespace below the name."""
    if not names.is_legal_name(param_name):
        warnings.warn(f"'{param_name}' is not a legal ROS graph resource name. This may cause problems with "
                      "other ROS tools", stacklevel=2)
    resolved = _resolve(param_name)
    code, msg, _value = _call_master("setParam", resolved, param_value)
    if code != 1:
        raise ROSException(f"cannot set parameter: {msg}")
    try:
        _cache.update(resolved, param_value)
    except KeyError:
        pass


def has_param(param_name: str) -> bool:
    """Whether ``param_name`` is set (a key or a namespace)."""
    code, msg, value = _call_master("hasParam", _resolve(param_name))
    if code != 1:
        raise ROSException(f"cannot check parameter on server: {msg}")
    return bool(value)


def delete_param(param_name: str) -> None:
    """Delete ``param_name``; KeyError(param_name) if it is not set."""
    code, msg, _value = _call_master("deleteParam", _resolve(param_name))
    if code == -1:
        raise KeyError(param_name)
    if code != 1:
        raise ROSException(f"cannot delete parameter: {msg}")


def search_param(param_name: str) -> str | None:
    """The closest key named ``param_name`` up the node's namespace, or None."""
    mappings = _mappings()
    key = mappings.get(param_name, param_name)  # rospy maps the unresolved key
    code, msg, value = _call_master("searchParam", key)
    if code == 1:
        return value
    if code == -1:
        return None
    raise ROSException(f"cannot search for parameter: {msg}")


def get_param_names() -> List[str]:
    """Every parameter key on the server."""
    code, msg, value = _call_master("getParamNames")
    if code != 1:
        raise ROSException(f"Unable to retrieve parameter names: {msg}")
    return value
