"""The ROS Master API as one typed client: every method a typed call, every answer checked once.

:class:`MasterClient` is what the node runtime, the client library, the tools and the web server
call the master with (goroslib's ``apimaster.Client``). It fills in the caller id, keeps one
kept-alive XML-RPC connection per thread (a lookupService per service call or a getParam per
parameter read must not each pay for a TCP connection), and turns every answer into a value or
one of three exceptions:

* :class:`MasterError` (code -1, the call was wrong: an unset parameter, an unknown node),
* :class:`MasterFailure` (code 0, a fault or a malformed answer: the master failed),
* :class:`MasterIOError` (an ``OSError``: the master could not be reached; ``errcode`` is the
  HTTP status when it answered one, e.g. 403 outside ROS_ALLOWED_HOSTS).

The first two are :mod:`minros.wire.rosapi`'s ``CallerError``/``CalleeFailure`` under
rosgraph's names, so one ``except RemoteError`` covers every code a ROS API answers.
:meth:`MasterClient.raw` keeps the ``[code, msg, value]`` triplet for rospy's MasterProxy, whose
users read it themselves. This module only builds on :mod:`minros.wire.xmlrpc`'s ServerProxy.
"""

from __future__ import annotations

import threading
import xmlrpc.client
from typing import Any, Callable, Dict, List, NamedTuple, Sequence, Tuple, Union
from xml.parsers.expat import ExpatError

from minros.wire.rosapi import CalleeFailure, CallerError, RemoteError, unwrap
from minros.wire.xmlrpc import ServerProxy

__all__ = [
    "MasterClient", "MasterError", "MasterException", "MasterFailure", "MasterIOError",
    "RemoteError", "SystemState",
]

#: rosgraph's names for the exceptions of a non-SUCCESS answer
MasterException = RemoteError
MasterError = CallerError
MasterFailure = CalleeFailure

#: a value, or a function asked on every call (a node's caller id changes at init_node, its
#: master URI may change until then)
Source = Union[str, Callable[[], str]]

#: ``[name, [node, ...]]`` pairs of getSystemState, one list per kind
Registrations = List[Tuple[str, List[str]]]


class SystemState(NamedTuple):
    """getSystemState: who publishes, subscribes to and provides what."""

    publishers: Registrations
    subscribers: Registrations
    services: Registrations


class MasterIOError(OSError):
    """The master could not be reached, or answered with an HTTP error (``errcode``)."""

    def __init__(self, message: str, errcode: int | None = None, errmsg: str = "") -> None:
        super().__init__(message)
        self.errcode = errcode
        self.errmsg = errmsg


class MasterClient:
    """The Master API of the master at ``uri`` as ``caller_id`` (both a value or a function).

    Thread-safe: each thread calls on its own kept-alive connection. ``timeout`` bounds every
    call (connect and answer)."""

    def __init__(self, uri: Source, caller_id: Source, timeout: float | None = 10.0) -> None:
        self._uri = uri
        self._caller_id = caller_id
        self.timeout = timeout
        self._local = threading.local()

    def with_timeout(self, timeout: float | None) -> MasterClient:
        """The same master and caller with another timeout (connections of its own)."""
        return MasterClient(self._uri, self._caller_id, timeout)

    @property
    def uri(self) -> str:
        uri = self._uri
        return uri if isinstance(uri, str) else uri()

    @property
    def caller_id(self) -> str:
        caller_id = self._caller_id
        return caller_id if isinstance(caller_id, str) else caller_id()

    # -- the one call path --------------------------------------------------------------------

    def _proxy(self) -> ServerProxy:
        uri = self.uri
        proxy: ServerProxy | None = getattr(self._local, "proxy", None)
        if proxy is None or proxy.uri != uri:
            try:
                proxy = ServerProxy(uri, timeout=self.timeout)
            except ValueError:
                raise MasterIOError(f"invalid ROS_MASTER_URI [{uri}]") from None
            self._local.proxy = proxy
        return proxy

    def raw(self, method: str, *args: Any) -> Any:
        """``method(caller_id, *args)`` as the master answers it (a triplet, unchecked)."""
        proxy = self._proxy()
        try:
            return getattr(proxy, method)(self.caller_id, *args)
        except xmlrpc.client.Fault as exc:
            raise MasterFailure(0, f"{method}: {exc.faultString}") from None
        except (ExpatError, ValueError) as exc:  # not XML-RPC, or a DTD in it
            self._local.proxy = None
            raise MasterFailure(0, f"{method}: malformed answer: {exc}") from None
        except xmlrpc.client.ProtocolError as exc:
            # str() of wire.xmlrpc's CallRefused/BadReply is the one line naming the cause (a
            # request over the 64 MiB limit, a host outside ROS_ALLOWED_HOSTS): kept, and the
            # cause chained, since that line is what the tools print
            self._local.proxy = None
            raise MasterIOError(str(exc), exc.errcode, exc.errmsg) from exc
        except (xmlrpc.client.ResponseError, OSError) as exc:
            self._local.proxy = None
            raise MasterIOError(str(exc)) from None

    def call(self, method: str, *args: Any) -> Any:
        """``method(caller_id, *args)``: the value of a SUCCESS answer, else the exceptions
        of this module."""
        return unwrap(self.raw(method, *args))

    def multicall(self, calls: Sequence[Dict[str, Any]]) -> List[Any]:
        """``system.multicall``: one request for many calls (``{"methodName", "params"}``);
        one raw answer per call."""
        try:
            return list(self._proxy().system.multicall(list(calls)))
        except xmlrpc.client.Fault as exc:
            raise MasterFailure(0, f"system.multicall: {exc.faultString}") from None
        except (xmlrpc.client.ProtocolError, xmlrpc.client.ResponseError, OSError) as exc:
            self._local.proxy = None
            raise MasterIOError(str(exc)) from exc

    def close(self) -> None:
        """Close this thread's connection (the next call opens another)."""
        proxy = getattr(self._local, "proxy", None)
        self._local.proxy = None
        if proxy is not None:
            proxy.close()

    # -- registration -------------------------------------------------------------------------

    def register_publisher(self, topic: str, topic_type: str, caller_api: str) -> List[str]:
        """The XML-RPC URIs of the topic's subscribers."""
        return list(self.call("registerPublisher", topic, topic_type, caller_api))

    def unregister_publisher(self, topic: str, caller_api: str) -> int:
        return int(self.call("unregisterPublisher", topic, caller_api))

    def register_subscriber(self, topic: str, topic_type: str, caller_api: str) -> List[str]:
        """The XML-RPC URIs of the topic's publishers."""
        return list(self.call("registerSubscriber", topic, topic_type, caller_api))

    def unregister_subscriber(self, topic: str, caller_api: str) -> int:
        return int(self.call("unregisterSubscriber", topic, caller_api))

    def register_service(self, service: str, service_api: str, caller_api: str) -> None:
        self.call("registerService", service, service_api, caller_api)

    def unregister_service(self, service: str, service_api: str) -> int:
        return int(self.call("unregisterService", service, service_api))

    # -- lookups ------------------------------------------------------------------------------

    def lookup_node(self, node_name: str) -> str:
        """The node's XML-RPC URI."""
        return str(self.call("lookupNode", node_name))

    def lookup_service(self, service: str) -> str:
        """The service's ``rosrpc://host:port`` URI."""
        return str(self.call("lookupService", service))

    def get_published_topics(self, subgraph: str = "") -> List[Tuple[str, str]]:
        """``(topic, type)`` of every published topic in ``subgraph``."""
        return [(topic, type_) for topic, type_ in self.call("getPublishedTopics", subgraph)]

    def get_topic_types(self) -> List[Tuple[str, str]]:
        """``(topic, type)`` of every topic the master knows a type for."""
        return [(topic, type_) for topic, type_ in self.call("getTopicTypes")]

    def get_system_state(self) -> SystemState:
        pubs, subs, srvs = self.call("getSystemState")
        return SystemState(pubs, subs, srvs)

    def get_uri(self) -> str:
        return str(self.call("getUri"))

    def get_pid(self) -> int:
        return int(self.call("getPid"))

    # -- parameters ---------------------------------------------------------------------------

    def get_param(self, key: str) -> Any:
        """The value (a dict for a namespace); MasterError when ``key`` is not set."""
        return self.call("getParam", key)

    def set_param(self, key: str, value: Any) -> None:
        self.call("setParam", key, value)

    def delete_param(self, key: str) -> None:
        """MasterError when ``key`` is not set."""
        self.call("deleteParam", key)

    def has_param(self, key: str) -> bool:
        return bool(self.call("hasParam", key))

    def search_param(self, key: str) -> str | None:
        """The closest ``key`` up the caller's namespace, or None when there is none."""
        try:
            return str(self.call("searchParam", key))
        except MasterError:
            return None

    def get_param_names(self) -> List[str]:
        return list(self.call("getParamNames"))

    def subscribe_param(self, caller_api: str, key: str) -> Any:
        """The current value (``{}`` when unset); ``paramUpdate`` calls follow."""
        return self.call("subscribeParam", caller_api, key)

    def unsubscribe_param(self, caller_api: str, key: str) -> int:
        return int(self.call("unsubscribeParam", caller_api, key))
