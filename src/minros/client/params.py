"""The parameter server from a node: rospy's get/set/has/delete/search_param and friends.

Names resolve like every other graph name (caller's namespace, ``~`` = the node's private
namespace, remappings applied to the resolved name). ``get_param_cached`` subscribes to the key
on the master (``subscribeParam``) and keeps a local tree fresh from the master's
``paramUpdate`` calls; plain ``get_param`` answers from that tree too once a key is cached, and
``set_param`` updates it, as rospy does.

:class:`ParamServer` is the API written once, over one master client; the rospy functions use
the node's master, rospy's ``MasterProxy`` (``get_master()[key]``) its own. It works before
``init_node`` (caller id ``/unnamed`` in the namespace, master from ``__master:=`` or
ROS_MASTER_URI).
"""

from __future__ import annotations

import threading
import warnings
from typing import Any, Callable, Dict, List, Tuple

from minros import names, node
from minros.exceptions import ROSException
from minros.wire.masterapi import MasterClient, MasterError, RemoteError

__all__ = [
    "ParamServer",
    "delete_param",
    "get_param",
    "get_param_cached",
    "get_param_names",
    "has_param",
    "search_param",
    "set_param",
]

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
            d, last = self._holder(key)
            d[last] = value

    def _holder(self, key: str) -> Tuple[dict, str]:
        """The cached dict holding ``key`` and its last name; KeyError if ``key`` is not cached.
        The caller holds the lock."""
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
        return d, parts[-1]

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
            d, last = self._holder(key)
            del d[last]

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


# --------------------------------------------------------------------------- the API


class _Unspecified:
    def __repr__(self) -> str:
        return "<unspecified>"


_unspecified: Any = _Unspecified()


class ParamServer:
    """The parameter server as rospy presents it, over the master ``master()`` returns: names
    resolved against the node, values answered from the node's cache once a key is cached."""

    def __init__(self, master: Callable[[], MasterClient]) -> None:
        self._master = master

    def get(self, param_name: str, default: Any = _unspecified) -> Any:
        """The value of ``param_name``; ``default`` if unset, else KeyError(param_name)."""
        resolved = node.resolve_name(param_name)
        try:
            return _cache.get(resolved)
        except KeyError:
            pass
        try:
            return self._master().get_param(resolved)
        except RemoteError:
            if default is not _unspecified:
                return default
            raise KeyError(param_name) from None

    def get_cached(self, param_name: str, default: Any = _unspecified) -> Any:
        """Like ``get``, but subscribes to the key and answers locally from then on."""
        resolved = node.resolve_name(param_name)
        try:
            return _cache.get(resolved)
        except KeyError:
            pass
        if _cache.is_unset(resolved):  # subscribed, and not set since: no need to ask again
            if default is not _unspecified:
                return default
            raise KeyError(param_name)
        if not node.get_node_uri():
            # no node to receive paramUpdate: a plain lookup is the best we can do
            return self.get(param_name, default)
        _install_update_handler()
        value = node.subscribe_param(resolved)
        if isinstance(value, dict) and not value:  # subscribeParam answers {} for an unset key
            _cache.mark_unset(resolved)
            if default is not _unspecified:
                return default
            raise KeyError(param_name)
        _cache.set(resolved, value)
        return value

    def set(self, param_name: str, param_value: Any) -> None:
        """Set ``param_name``; a dict replaces the whole namespace below the name."""
        resolved = node.resolve_name(param_name)
        try:
            self._master().set_param(resolved, param_value)
        except RemoteError as exc:
            raise ROSException(f"cannot set parameter: {exc}") from None
        try:
            _cache.update(resolved, param_value)
        except KeyError:
            pass

    def has(self, param_name: str) -> bool:
        """Whether ``param_name`` is set (a key or a namespace)."""
        try:
            return self._master().has_param(node.resolve_name(param_name))
        except RemoteError as exc:
            raise ROSException(f"cannot check parameter on server: {exc}") from None

    def delete(self, param_name: str) -> None:
        """Delete ``param_name``; KeyError(param_name) if it is not set."""
        try:
            self._master().delete_param(node.resolve_name(param_name))
        except MasterError:
            raise KeyError(param_name) from None
        except RemoteError as exc:
            raise ROSException(f"cannot delete parameter: {exc}") from None

    def search(self, param_name: str) -> str | None:
        """The closest key named ``param_name`` up the node's namespace, or None."""
        key = node.get_mappings().get(param_name, param_name)  # rospy maps the unresolved key
        try:
            return self._master().search_param(key)
        except RemoteError as exc:
            raise ROSException(f"cannot search for parameter: {exc}") from None

    def names(self) -> List[str]:
        """Every parameter key on the server."""
        try:
            return self._master().get_param_names()
        except RemoteError as exc:
            raise ROSException(f"Unable to retrieve parameter names: {exc}") from None


#: the node's parameter server (rospy's module functions below)
_server = ParamServer(node.master)


def get_param(param_name: str, default: Any = _unspecified) -> Any:
    """The value of ``param_name``; ``default`` if unset, else KeyError(param_name)."""
    return _server.get(param_name, default)


def get_param_cached(param_name: str, default: Any = _unspecified) -> Any:
    """Like ``get_param``, but subscribes to the key and answers locally from then on."""
    return _server.get_cached(param_name, default)


def set_param(param_name: str, param_value: Any) -> None:
    """Set ``param_name``; a dict replaces the whole namespace below the name."""
    if not names.is_legal_name(param_name):
        warnings.warn(f"'{param_name}' is not a legal ROS graph resource name. This may cause problems with "
                      "other ROS tools", stacklevel=2)
    _server.set(param_name, param_value)


def has_param(param_name: str) -> bool:
    """Whether ``param_name`` is set (a key or a namespace)."""
    return _server.has(param_name)


def delete_param(param_name: str) -> None:
    """Delete ``param_name``; KeyError(param_name) if it is not set."""
    _server.delete(param_name)


def search_param(param_name: str) -> str | None:
    """The closest key named ``param_name`` up the node's namespace, or None."""
    return _server.search(param_name)


def get_param_names() -> List[str]:
    """Every parameter key on the server."""
    return _server.names()
