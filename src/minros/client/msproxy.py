"""rospy's MasterProxy: the master's XML-RPC API with the caller_id filled in and names
resolved, and a dict-like view of the parameter server (``get_master()['/foo']``)."""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, Iterator

from minros import node, rosenv
from minros.client import params
from minros.exceptions import ROSException
from minros.wire.xmlrpc import ServerProxy

__all__ = ["MasterProxy", "get_master"]

#: master methods whose arguments (by position after caller_id) are names to resolve
_MASTER_ARG_REMAP = {
    "deleteParam": [0], "setParam": [0], "getParam": [0], "searchParam": [0],
    "subscribeParam": [1], "unsubscribeParam": [1], "hasParam": [0],
    "registerService": [0], "lookupService": [0], "unregisterService": [0],
    "registerSubscriber": [0], "unregisterSubscriber": [0],
    "registerPublisher": [0], "unregisterPublisher": [0],
    "lookupNode": [0], "getPublishedTopics": [0],
}


class MasterProxy:
    """The master's XML-RPC API with caller_id filled in and names resolved (rospy.MasterProxy);
    also a dict-like view of the parameter server."""

    def __init__(self, uri: str) -> None:
        self.target = ServerProxy(uri, timeout=node.XMLRPC_TIMEOUT)

    def __getattr__(self, key: str) -> Callable[..., Any]:
        if key.startswith("__"):
            raise AttributeError(key)
        remap = _MASTER_ARG_REMAP.get(key, [])

        def call(*args: Any) -> Any:
            full = [node.get_caller_id(), *args]
            for i in remap:
                if i + 1 < len(full):
                    full[i + 1] = node.resolve_name(full[i + 1])
            return getattr(self.target, key)(*full)

        return call

    def __getitem__(self, key: str) -> Any:
        code, _msg, value = self.target.getParam(node.get_caller_id(), node.resolve_name(key))
        if code != 1:
            raise KeyError(key)
        return value

    def __setitem__(self, key: str, value: Any) -> None:
        self.target.setParam(node.get_caller_id(), node.resolve_name(key), value)

    def __delitem__(self, key: str) -> None:
        code, msg, _ = self.target.deleteParam(node.get_caller_id(), node.resolve_name(key))
        if code == -1:
            raise KeyError(key)
        if code != 1:
            raise ROSException(f"cannot delete parameter: {msg}")

    def __contains__(self, key: str) -> bool:
        code, msg, value = self.target.hasParam(node.get_caller_id(), node.resolve_name(key))
        if code != 1:
            raise ROSException(f"cannot check parameter on server: {msg}")
        return bool(value)

    def __iter__(self) -> Iterator[str]:
        code, msg, value = self.target.getParamNames(node.get_caller_id())
        if code != 1:
            raise ROSException(f"cannot retrieve parameter names: {msg}")
        return iter(value)

    def search_param(self, key: str) -> str | None:
        key = node.get_mappings().get(key, key)
        code, msg, value = self.target.searchParam(node.get_caller_id(), key)
        if code == 1:
            return value
        if code == -1:
            return None
        raise ROSException(f"cannot search for parameter: {msg}")

    def get_param_cached(self, key: str) -> Any:
        return params.get_param_cached(key)


def get_master(env: Dict[str, str] | None = None) -> MasterProxy:
    """A MasterProxy for ROS_MASTER_URI (or ``env``'s)."""
    if env is not None and env is not os.environ:
        uri = rosenv.get_master_uri(env)
    else:
        uri = node.get_master_uri()
    return MasterProxy(uri)
