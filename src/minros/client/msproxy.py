"""rospy's MasterProxy: the master's XML-RPC API with the caller_id filled in and names
resolved, and a dict-like view of the parameter server (``get_master()['/foo']``).

Both halves sit on the one master client (:class:`minros.wire.masterapi.MasterClient`): the
method calls return the raw ``[code, msg, value]`` triplet, as rospy's do, and the dict view is
:class:`minros.client.params.ParamServer`, the parameter API rospy's functions use too.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, Iterator

from minros import node, rosenv
from minros.client.params import ParamServer
from minros.wire.masterapi import MasterClient
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
        self._client = MasterClient(uri, node.get_caller_id, node.XMLRPC_TIMEOUT)
        self._params = ParamServer(lambda: self._client)

    @property
    def target(self) -> ServerProxy:
        """The XML-RPC proxy of the master (rospy's attribute)."""
        return self._client._proxy()

    def __getattr__(self, key: str) -> Callable[..., Any]:
        if key.startswith("_"):
            raise AttributeError(key)
        remap = _MASTER_ARG_REMAP.get(key, [])

        def call(*args: Any) -> Any:
            full = list(args)
            for i in remap:
                if i < len(full):
                    full[i] = node.resolve_name(full[i])
            return self._client.raw(key, *full)

        return call

    def __getitem__(self, key: str) -> Any:
        return self._params.get(key)

    def __setitem__(self, key: str, value: Any) -> None:
        self._params.set(key, value)

    def __delitem__(self, key: str) -> None:
        self._params.delete(key)

    def __contains__(self, key: str) -> bool:
        return self._params.has(key)

    def __iter__(self) -> Iterator[str]:
        return iter(self._params.names())

    def search_param(self, key: str) -> str | None:
        return self._params.search(key)

    def get_param_cached(self, key: str) -> Any:
        return self._params.get_cached(key)


def get_master(env: Dict[str, str] | None = None) -> MasterProxy:
    """A MasterProxy for ROS_MASTER_URI (or ``env``'s)."""
    if env is not None and env is not os.environ:
        uri = rosenv.get_master_uri(env)
    else:
        uri = node.get_master_uri()
    return MasterProxy(uri)
