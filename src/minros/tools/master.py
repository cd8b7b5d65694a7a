"""A master client for command-line tools (rosgraph.Master semantics, bounded timeouts).

``Master(caller_id).getParam('/x')`` returns the value of a SUCCESS triplet, raises
:class:`MasterError` for code -1, :class:`MasterFailure` for code 0, and
:class:`MasterIOError` (an ``OSError``) when the master cannot be reached at all.
"""

from __future__ import annotations

import sys
import xmlrpc.client
from typing import Any, Dict, List, Tuple

from minros import names, rosenv
from minros.wire.xmlrpc import ServerProxy

DEFAULT_MASTER_URI = rosenv.DEFAULT_MASTER_URI
#: seconds to wait for any single XML-RPC answer; a tool never hangs on a dead peer
TOOL_TIMEOUT = 5.0


#: substrings that mark debug nodes and topics (/rosout, /rosout_agg, /clock, rqt, rviz, ...):
#: rqt_graph's "Hide Debug", which minros graph and the web page's graph apply too
QUIET_NAMES = ("/diag_agg", "/runtime_logger", "/pr2_dashboard", "/rviz", "/rosout", "/cpu_monitor",
               "/monitor", "/hd_monitor", "/rxloggerlevel", "/clock", "/rqt", "/statistics", "/rosapi")


def is_quiet(name: str) -> bool:
    return any(q in name for q in QUIET_NAMES)


class MasterException(Exception):
    """Base of master call errors."""


class MasterError(MasterException):
    """The master answered code -1 (caller error: unknown name, unset parameter...)."""


class MasterFailure(MasterException):
    """The master answered code 0 (it tried and failed)."""


class MasterIOError(OSError):
    """The master could not be reached."""


def get_master_uri(argv: List[str] | None = None) -> str:
    """``__master:=`` beats ``ROS_MASTER_URI``; default ``http://localhost:11311/``."""
    return rosenv.get_master_uri(remapped=rosenv.remapped_master(sys.argv if argv is None else argv))


def call_node(uri: str, method: str, *args: Any, timeout: float = TOOL_TIMEOUT) -> list:
    """Raw triplet of ``method`` on a node's XML-RPC API (OSError on network failure)."""
    try:
        proxy = ServerProxy(uri, timeout=timeout)
    except ValueError as exc:
        raise OSError(str(exc)) from None
    try:
        return getattr(proxy, method)(*args)
    except (xmlrpc.client.Fault, xmlrpc.client.ProtocolError, xmlrpc.client.ResponseError) as exc:
        raise OSError(f"XML-RPC error from {uri}: {exc}") from None
    finally:
        proxy.close()


#: rosgraph.masterapi's names for the same classes
ROSMasterException = MasterException
Error = MasterError
Failure = MasterFailure


class Master:
    """Calls master methods with ``caller_id`` prepended; results unwrapped as rosgraph does.

    This is rosgraph.Master: ``Master('/rostopic').getParam('/x')``; a relative caller id is
    put in the ROS namespace. Every call is bounded by ``timeout`` seconds.
    """

    def __init__(self, caller_id: str, master_uri: str | None = None,
                 timeout: float = TOOL_TIMEOUT) -> None:
        caller_id = names.make_caller_id(caller_id)
        self.caller_id = caller_id[:-1] if caller_id.endswith("/") else caller_id
        self.uri = master_uri or get_master_uri()
        self.timeout = timeout
        self._proxy: ServerProxy | None = None

    @property
    def master_uri(self) -> str:
        return self.uri

    @property
    def handle(self) -> ServerProxy:
        """The XML-RPC proxy of the master (rosgraph's name; tests replace it by a mock)."""
        return self._get_proxy()

    @handle.setter
    def handle(self, proxy: Any) -> None:
        self._proxy = proxy

    def is_online(self) -> bool:
        """Whether the master answers ``getPid``."""
        try:
            self.getPid()
            return True
        except Exception:  # noqa: BLE001 - any failure means "not online", as in rosgraph
            return False

    def _get_proxy(self) -> ServerProxy:
        if self._proxy is None:
            try:
                self._proxy = ServerProxy(self.uri, timeout=self.timeout)
            except ValueError:
                raise MasterIOError(f"invalid ROS_MASTER_URI [{self.uri}]") from None
        return self._proxy

    def raw(self, method: str, *args: Any) -> list:
        """The raw ``[code, msg, value]`` triplet."""
        try:
            return getattr(self._get_proxy(), method)(self.caller_id, *args)
        except xmlrpc.client.Fault as exc:
            raise MasterFailure(f"{method}: {exc.faultString}") from None
        except (xmlrpc.client.ProtocolError, xmlrpc.client.ResponseError) as exc:
            raise MasterIOError(str(exc)) from exc  # a CallError's line is what tools print
        except OSError as exc:
            raise MasterIOError(str(exc)) from None

    def call(self, method: str, *args: Any) -> Any:
        result = self.raw(method, *args)
        if not isinstance(result, (list, tuple)) or len(result) != 3:
            raise MasterFailure(f"malformed result of {method}: {result!r}")
        code, msg, value = result
        if code == 1:
            return value
        if code == -1:
            raise MasterError(str(msg))
        raise MasterFailure(str(msg))

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_") or name in ("uri", "timeout", "caller_id"):
            raise AttributeError(name)
        return lambda *args: self.call(name, *args)

    def close(self) -> None:
        if self._proxy is not None:
            self._proxy.close()
            self._proxy = None

    # -- helpers used by several tools --------------------------------------------------------
    def system_state(self) -> Tuple[list, list, list]:
        pubs, subs, srvs = self.call("getSystemState")
        return pubs, subs, srvs

    def topic_types(self) -> List[List[str]]:
        try:
            return self.call("getTopicTypes")
        except MasterFailure:
            return self.call("getPublishedTopics", "/")

    def lookup_node_cached(self, cache: Dict[str, str | None], node: str) -> str | None:
        if node not in cache:
            try:
                cache[node] = self.call("lookupNode", node)
            except MasterException:
                cache[node] = None
        return cache[node]


def is_online(master_uri: str | None = None) -> bool:
    """Whether the master at ``master_uri`` (default: the environment's) answers."""
    return Master("rosgraph", master_uri=master_uri).is_online()
