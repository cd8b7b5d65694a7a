"""A node's XML-RPC API, called by the master, the tools and other nodes (rospy's ROSHandler),
with rospy's argument checks and triplets (``wire/rosapi.api``)."""

from __future__ import annotations

import os
import urllib.parse
from typing import Any, List, Protocol, Tuple

from minros import names
from minros.node.registries import Registries
from minros.wire.rosapi import ParameterInvalid, api, is_topic
from minros.wire.xmlrpc import after_reply

__all__ = ["SlaveApi", "SlaveNode"]

_INT32_MAX = (1 << 31) - 1


def xmlrpc_ints(value: Any) -> Any:
    """Byte counters of a long-lived connection outgrow XML-RPC's 32-bit int: saturate them."""
    if isinstance(value, list):
        return [xmlrpc_ints(v) for v in value]
    if isinstance(value, int) and not isinstance(value, bool) and value > _INT32_MAX:
        return _INT32_MAX
    return value


class SlaveNode(Protocol):
    """What the slave API needs of its node (``minros.node.Node``)."""

    uri: str | None
    registries: Registries

    @property
    def name(self) -> str: ...
    @property
    def master_uri(self) -> str: ...
    def signal_shutdown(self, reason: str) -> None: ...
    def answer_protocol(self, topic: str, offer: Any) -> List[Any] | None: ...


class SlaveApi:
    """The slave API of ``node``."""

    def __init__(self, node: SlaveNode) -> None:
        self._node = node

    def _endpoints(self) -> Tuple[List[Any], List[Any]]:
        return self._node.registries.endpoints()

    @api("")
    def getUri(self, caller_id: str) -> Tuple[int, str, Any]:
        return 1, "", self._node.uri

    @api("")
    def getName(self, caller_id: str) -> Tuple[int, str, Any]:
        return 1, "", self._node.name

    @api([])
    def getBusStats(self, caller_id: str) -> Tuple[int, str, Any]:
        pubs, subs = self._endpoints()
        return 1, "", xmlrpc_ints([[p.get_stats() for p in pubs], [s.get_stats() for s in subs], []])

    @api([])
    def getBusInfo(self, caller_id: str) -> Tuple[int, str, Any]:
        pubs, subs = self._endpoints()
        info: List[Any] = []
        for endpoint in pubs + subs:
            info.extend(endpoint.get_stats_info())
        return 1, "bus info", info

    @api("")
    def getMasterUri(self, caller_id: str) -> Tuple[int, str, Any]:
        uri = self._node.master_uri
        if uri:
            return 1, uri, uri
        return 0, "master URI not set", ""

    @api(0, (None,))
    def shutdown(self, caller_id: str, msg: str = "") -> Tuple[int, str, Any]:
        if msg:
            print(f"shutdown request: {msg}", flush=True)
        else:
            print("shutdown requst", flush=True)  # sic: rospy's text, kept byte for byte
        reason = f"external shutdown request from [{caller_id}]: [{msg}]"
        # the reply leaves first, then the servers close
        after_reply(lambda: self._node.signal_shutdown(reason))
        return 1, "shutdown", 0

    @api(-1)
    def getPid(self, caller_id: str) -> Tuple[int, str, Any]:
        return 1, "", os.getpid()

    @api([])
    def getSubscriptions(self, caller_id: str) -> Tuple[int, str, Any]:
        _, subs = self._endpoints()
        return 1, "subscriptions", [[s.resolved_name, s.type] for s in subs]

    @api([])
    def getPublications(self, caller_id: str) -> Tuple[int, str, Any]:
        pubs, _ = self._endpoints()
        return 1, "publications", [[p.resolved_name, p.type] for p in pubs]

    @api(-1, (None, None))
    def paramUpdate(self, caller_id: str, key: Any, value: Any) -> Tuple[int, str, Any]:
        if not key or not isinstance(key, str):
            raise ParameterInvalid("ERROR: parameter [parameter_key] must be a non-empty string")
        if not names.is_global(key):
            raise ParameterInvalid("ERROR: parameter [parameter_key] must be a globally referenced name")
        if not self._node.registries.param_update(key, value):
            return -1, "not subscribed", 0
        return 1, "", 0

    @api(-1, (is_topic("topic"), None))
    def publisherUpdate(self, caller_id: str, topic: str, publishers: Any) -> Tuple[int, str, Any]:
        if not isinstance(publishers, list):
            raise ParameterInvalid("ERROR: param [publishers] must be a list")
        for uri in publishers:
            if not isinstance(uri, str):
                raise ParameterInvalid("ERROR: param [publishers] must be a list of strings")
            parsed = urllib.parse.urlparse(uri)
            if not parsed.scheme or not parsed.netloc:
                raise ParameterInvalid(f"ERROR: param [publishers] does not contain valid URLs [{uri}]")
        sub = self._node.registries.subscriptions.get(topic)
        if sub is not None:
            sub.publisher_update(publishers)
        return 1, "", 0

    @api([], (is_topic("topic"), None))
    def requestTopic(self, caller_id: str, topic: str, protocols: Any) -> Tuple[int, str, Any]:
        if not protocols:
            raise ParameterInvalid("ERROR: parameter [protocols] must be specified and non-empty")
        if not isinstance(protocols, list):
            raise ParameterInvalid("ERROR: parameter [protocols] must be a list of protocols")
        if topic not in self._node.registries.publications:
            return -1, f"Not a publisher of [{topic}]", []
        for offer in protocols:  # the subscriber's order: the first we speak wins
            answer = self._node.answer_protocol(topic, offer)
            if answer is not None:
                return 1, "ready on " + ":".join(str(p) for p in answer[1:3]), answer
        return 0, "no supported protocol implementations", []

