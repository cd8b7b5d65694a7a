"""The ROS Slave API (a node's XML-RPC API) as one typed client, as ``masterapi`` is the master's.

:class:`SlaveClient` is how a subscriber asks a publisher for a connection (``request_topic``),
how the tools ask a node what it is connected to (``get_bus_info``, ``get_pid``, ...) and how a
node is told to shut down. It fills in the caller id, keeps one kept-alive connection to the
node until :meth:`SlaveClient.close` (or the end of a ``with`` block), and turns every answer
into a value or one of these, in one place (:meth:`SlaveClient.call`):

* :class:`NodeError` (code -1: the call was wrong, e.g. "Not a publisher of [/t]"),
* :class:`NodeFailure` (code 0, a fault, or an answer that is not a triplet: the node failed),
* ``OSError``: the node could not be reached. A network error keeps its own class (a refused
  connection is a ``ConnectionRefusedError``, a silent node a ``TimeoutError``), so a caller
  can tell a node that is gone from one that is slow; an HTTP refusal is a
  :class:`NodeIOError` with its status.

The first two are :mod:`minros.wire.rosapi`'s ``CallerError``/``CalleeFailure``, so one
``except RemoteError`` covers every code a ROS API answers. This module only builds on
:mod:`minros.wire.xmlrpc`'s ServerProxy.
"""

from __future__ import annotations

import xmlrpc.client
from types import TracebackType
from typing import Any, Callable, List, Tuple, Union
from xml.parsers.expat import ExpatError

from minros.wire.rosapi import CalleeFailure, CallerError, RemoteError, unwrap
from minros.wire.xmlrpc import ServerProxy

__all__ = ["NodeError", "NodeFailure", "NodeIOError", "RemoteError", "SlaveClient"]

NodeError = CallerError
NodeFailure = CalleeFailure

#: a value, or a function asked on every call (a node's caller id changes at init_node)
Source = Union[str, Callable[[], str]]


class NodeIOError(OSError):
    """The node answered with an HTTP error (``errcode``), or its connection failed mid-call."""

    def __init__(self, message: str, errcode: int | None = None) -> None:
        super().__init__(message)
        self.errcode = errcode


class SlaveClient:
    """The Slave API of the node at ``uri`` (its XML-RPC URI) as ``caller_id``.

    ``timeout`` bounds every call (connect and answer). One connection, opened by the first
    call and kept alive until :meth:`close`; calls from several threads take turns on it."""

    def __init__(self, uri: str, caller_id: Source, timeout: float | None = 10.0) -> None:
        self.uri = uri
        self._caller_id = caller_id
        self.timeout = timeout
        self._proxy: ServerProxy | None = None

    @property
    def caller_id(self) -> str:
        caller_id = self._caller_id
        return caller_id if isinstance(caller_id, str) else caller_id()

    def __enter__(self) -> SlaveClient:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def close(self) -> None:
        proxy, self._proxy = self._proxy, None
        if proxy is not None:
            proxy.close()

    # -- the one call path --------------------------------------------------------------------

    def raw(self, method: str, *args: Any) -> Any:
        """``method(caller_id, *args)`` as the node answers it (a triplet, unchecked)."""
        proxy = self._proxy
        if proxy is None:
            try:
                proxy = self._proxy = ServerProxy(self.uri, timeout=self.timeout)
            except ValueError:
                raise NodeIOError(f"not a node's XML-RPC URI: [{self.uri}]") from None
        try:
            return getattr(proxy, method)(self.caller_id, *args)
        except xmlrpc.client.Fault as exc:
            raise NodeFailure(0, f"{method} of [{self.uri}]: {exc.faultString}") from None
        except xmlrpc.client.ProtocolError as exc:
            # wire.xmlrpc's CallRefused/BadReply: str() is the one line naming the cause
            self.close()
            raise NodeIOError(f"{method} of [{self.uri}]: {exc}", exc.errcode) from exc
        except (xmlrpc.client.ResponseError, ExpatError, ValueError) as exc:
            self.close()
            raise NodeFailure(0, f"{method} of [{self.uri}]: malformed answer: {exc}") from None
        except OSError:
            self.close()
            raise

    def call(self, method: str, *args: Any) -> Any:
        """``method(caller_id, *args)``: the value of a SUCCESS answer, else the exceptions of
        this module."""
        return unwrap(self.raw(method, *args))

    # -- topics -------------------------------------------------------------------------------

    def request_topic(self, topic: str, protocols: List[List[Any]]) -> List[Any]:
        """The publisher's choice among ``protocols`` (``[name, params...]`` each, in the order
        we prefer): ``[name, params...]`` of the one it took."""
        answer = self.call("requestTopic", topic, protocols)
        if not isinstance(answer, list) or not answer:
            raise NodeFailure(0, f"publisher returned invalid protocol choice: {answer}")
        return answer

    def publisher_update(self, topic: str, publishers: List[str]) -> None:
        """The publishers of ``topic`` now (the master's call to a subscriber)."""
        self.call("publisherUpdate", topic, publishers)

    def param_update(self, key: str, value: Any) -> None:
        """A subscribed parameter changed (the master's call)."""
        self.call("paramUpdate", key, value)

    def get_subscriptions(self) -> List[Tuple[str, str]]:
        """``(topic, type)`` of every topic the node subscribes to."""
        return [(str(t[0]), str(t[1])) for t in _rows(self.call("getSubscriptions"), 2)]

    def get_publications(self) -> List[Tuple[str, str]]:
        """``(topic, type)`` of every topic the node publishes."""
        return [(str(t[0]), str(t[1])) for t in _rows(self.call("getPublications"), 2)]

    # -- introspection ------------------------------------------------------------------------

    def get_bus_info(self) -> List[List[Any]]:
        """One row per connection: ``[id, peer, direction, transport, topic, connected, info]``
        (the first five are there in every node's answer)."""
        return _rows(self.call("getBusInfo"), 5)

    def get_bus_stats(self) -> List[Any]:
        """``[publish stats, subscribe stats, service stats]``."""
        stats = self.call("getBusStats")
        if not isinstance(stats, list):
            raise NodeFailure(0, f"malformed getBusStats answer from [{self.uri}]")
        return stats

    def get_pid(self) -> int:
        pid = self.call("getPid")
        if not isinstance(pid, int) or isinstance(pid, bool):
            raise NodeFailure(0, f"malformed getPid answer from [{self.uri}]: {pid!r}")
        return pid

    def get_master_uri(self) -> str:
        return str(self.call("getMasterUri"))

    def get_name(self) -> str:
        return str(self.call("getName"))

    def get_uri(self) -> str:
        return str(self.call("getUri"))

    def shutdown(self, msg: str = "") -> None:
        """Ask the node to shut down (it answers first, then stops)."""
        self.call("shutdown", msg)


def _rows(value: Any, width: int) -> List[List[Any]]:
    """``value`` as a list of lists of at least ``width`` items (NodeFailure otherwise)."""
    if not isinstance(value, list) or not all(isinstance(r, list) and len(r) >= width
                                              for r in value):
        raise NodeFailure(0, f"malformed answer: {str(value)[:200]}")
    return value
