"""rosgraph.Master for the command-line tools: the one master client with rosgraph's face.

``Master(caller_id).getParam('/x')`` returns the value of a SUCCESS triplet, raises
:class:`MasterError` for code -1, :class:`MasterFailure` for code 0, and
:class:`MasterIOError` (an ``OSError``) when the master cannot be reached at all: it is
:class:`minros.wire.masterapi.MasterClient` (typed methods, one error path) with rosgraph's
camelCase calls and a bounded timeout, so no tool hangs on a dead master.
"""

from __future__ import annotations

import sys
from typing import Any, Dict, List, Tuple

from minros import names, rosenv
from minros.wire.masterapi import (
    MasterClient,
    MasterError,
    MasterException,
    MasterFailure,
    MasterIOError,
)
from minros.wire.xmlrpc import ServerProxy

__all__ = [
    "Error", "Failure", "Master", "MasterError", "MasterException", "MasterFailure",
    "MasterIOError", "QUIET_NAMES", "ROSMasterException", "get_master_uri",
    "is_online", "is_quiet",
]

DEFAULT_MASTER_URI = rosenv.DEFAULT_MASTER_URI
#: seconds to wait for any single XML-RPC answer; a tool never hangs on a dead peer
TOOL_TIMEOUT = 5.0


#: substrings that mark debug nodes and topics (/rosout, /rosout_agg, /clock, rqt, rviz, ...):
#: rqt_graph's "Hide Debug", which minros graph and the web page's graph apply too
QUIET_NAMES = ("/diag_agg", "/runtime_logger", "/pr2_dashboard", "/rviz", "/rosout", "/cpu_monitor",
               "/monitor", "/hd_monitor", "/rxloggerlevel", "/clock", "/rqt", "/statistics", "/rosapi")


def is_quiet(name: str) -> bool:
    return any(q in name for q in QUIET_NAMES)


def get_master_uri(argv: List[str] | None = None) -> str:
    """``__master:=`` beats ``ROS_MASTER_URI``; default ``http://localhost:11311/``."""
    return rosenv.get_master_uri(remapped=rosenv.remapped_master(sys.argv if argv is None else argv))


#: rosgraph.masterapi's names for the same classes
ROSMasterException = MasterException
Error = MasterError
Failure = MasterFailure


class Master(MasterClient):
    """rosgraph.Master: ``Master('/rostopic').getParam('/x')``, master methods with
    ``caller_id`` prepended and the answer unwrapped. A relative caller id is put in the ROS
    namespace; every call is bounded by ``timeout`` seconds."""

    _handle: Any = None

    def __init__(self, caller_id: str, master_uri: str | None = None,
                 timeout: float = TOOL_TIMEOUT) -> None:
        caller_id = names.make_caller_id(caller_id)
        super().__init__(master_uri or get_master_uri(),
                         caller_id[:-1] if caller_id.endswith("/") else caller_id, timeout)

    @property
    def master_uri(self) -> str:
        return self.uri

    @property
    def handle(self) -> ServerProxy:
        """The XML-RPC proxy of the master (rosgraph's name; tests replace it by a mock)."""
        return self._proxy()

    @handle.setter
    def handle(self, proxy: Any) -> None:
        self._handle = proxy

    def is_online(self) -> bool:
        """Whether the master answers ``getPid``."""
        try:
            self.get_pid()
            return True
        except Exception:  # noqa: BLE001 - any failure means "not online", as in rosgraph
            return False

    def _proxy(self) -> ServerProxy:
        # a proxy set through ``handle`` (rosgraph's tests set a mock) answers every call
        return self._handle if self._handle is not None else super()._proxy()

    def __getattr__(self, name: str) -> Any:
        # rosgraph's API: any master method by its XML-RPC name
        if name.startswith("_") or not name[:1].islower():
            raise AttributeError(name)
        return lambda *args: self.call(name, *args)

    # -- helpers used by several tools --------------------------------------------------------
    def system_state(self) -> Tuple[list, list, list]:
        pubs, subs, srvs = self.get_system_state()
        return pubs, subs, srvs

    def topic_types(self) -> List[Tuple[str, str]]:
        """getTopicTypes, or getPublishedTopics from a master without it."""
        try:
            return self.get_topic_types()
        except MasterFailure:
            return self.get_published_topics("/")

    def lookup_node_cached(self, cache: Dict[str, str | None], node: str) -> str | None:
        if node not in cache:
            try:
                cache[node] = self.lookup_node(node)
            except MasterException:
                cache[node] = None
        return cache[node]


def is_online(master_uri: str | None = None) -> bool:
    """Whether the master at ``master_uri`` (default: the environment's) answers."""
    return Master("rosgraph", master_uri=master_uri).is_online()
