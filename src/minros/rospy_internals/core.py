"""rospy.core: the node's life cycle and URI, logging set-up, rosrpc URIs and XML-RPC proxies,
with rospy's names, over minros's default node (:mod:`minros.node`).

``rospy.core`` *is* this module. rospy keeps its shutdown state in module globals, which code
(rospy's own tests among it) reads and sets; here the state is the node's, and the globals
are properties of the module object: ``_shutdown_flag`` and ``_in_shutdown`` read the node,
and setting them back to False gives the process a fresh node (what rospy's tests do to
reuse one process). The hook lists are rospy's own, run by the node's shutdown in rospy's
order: client hooks, pre-shutdown hooks, then (with the flag set) shutdown hooks.
"""

from __future__ import annotations

import hashlib
import logging
import os
import sys
import threading
import time
import types
import warnings
import xmlrpc.client
from typing import Any, Callable, Dict, List, Mapping, Optional
from urllib.parse import urlparse

from minros import node as _node
from minros import roslogging
from minros.client.log import (  # noqa: F401 - rospy.core's logging functions
    logdebug,
    logdebug_once,
    logdebug_throttle,
    logdebug_throttle_identical,
    logerr,
    logerr_once,
    logerr_throttle,
    logerr_throttle_identical,
    logfatal,
    logfatal_once,
    logfatal_throttle,
    logfatal_throttle_identical,
    loginfo,
    loginfo_once,
    loginfo_throttle,
    loginfo_throttle_identical,
    logwarn,
    logwarn_once,
    logwarn_throttle,
    logwarn_throttle_identical,
)
from minros.exceptions import ROSException
from minros.rospy_internals.names import (  # noqa: F401 - rospy.core does `from rospy.names import *`
    ANYTYPE,
    GLOBALNS,
    REMAP,
    SEP,
    SERVICE_ANYTYPE,
    TOPIC_ANYTYPE,
    ROSInitException,
    canonicalize_name,
    get_caller_id,
    get_mappings,
    get_name,
    get_namespace,
    get_resolved_mappings,
    get_ros_namespace,
    global_name,
    initialize_mappings,
    is_global,
    is_private,
    isstring,
    load_mappings,
    make_global_ns,
    namespace,
    ns_join,
    reload_mappings,
    remap_name,
    resolve_name,
    resolve_name_without_node_name,
    scoped_name,
    valid_name_validator_resolved,
    valid_name_validator_unresolved,
)
from minros.wire.rosapi import (  # noqa: F401
    ROSRPC,
    ParameterInvalid,
    parse_rosrpc_uri,  # noqa: F401
)
from minros.wire.rosapi import is_topic as _is_topic
from minros.wire.rosapi import valid_name as _valid_name

_logger = logging.getLogger("rospy.core")
_rospy_logger = logging.getLogger("rospy.internal")

MASTER_NAME = "master"  # the node name reserved for the master
_TIMEOUT_SHUTDOWN_JOIN = 5.0
#: seconds an XML-RPC call made through xmlrpcapi() may take
XMLRPC_TIMEOUT = 10.0

logout = loginfo
logerror = logerr


def rospydebug(msg: str, *args: Any, **kwargs: Any) -> None:
    _rospy_logger.debug(msg, *args, **kwargs)


def rospyinfo(msg: str, *args: Any, **kwargs: Any) -> None:
    _rospy_logger.info(msg, *args, **kwargs)


def rospyerr(msg: str, *args: Any, **kwargs: Any) -> None:
    _rospy_logger.error(msg, *args, **kwargs)


def rospywarn(msg: str, *args: Any, **kwargs: Any) -> None:
    _rospy_logger.warning(msg, *args, **kwargs)


def deprecated(func: Callable) -> Callable:
    """Mark ``func`` deprecated: each call warns."""
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        warnings.warn(f"Call to deprecated function {func.__name__}.",
                      category=DeprecationWarning, stacklevel=2)
        return func(*args, **kwargs)
    wrapper.__name__ = func.__name__
    wrapper.__doc__ = func.__doc__
    return wrapper


class NullHandler(logging.Handler):
    def emit(self, record: logging.LogRecord) -> None:
        pass


# rospy's call-site filters of the log*_throttle/_identical/_once functions, as classes code can
# use on its own keys (minros's log functions keep their own per-call-site state).

class LoggingThrottle:
    """``throttle(caller_id, period)`` is True at most once per ``period`` seconds of ROS time
    for each ``caller_id`` (and again at once when time jumps backwards)."""

    def __init__(self) -> None:
        self.last_logging_time_table: Dict[Any, float] = {}

    def __call__(self, caller_id: Any, period: float) -> bool:
        from minros.client import rostime

        now = rostime.get_time() if rostime.is_rostime_initialized() else time.time()
        last = self.last_logging_time_table.get(caller_id)
        if last is None or now - last > period:
            self.last_logging_time_table[caller_id] = now
            return True
        if last > now:
            self.last_logging_time_table = {caller_id: now}
            return True
        return False


class LoggingIdentical:
    """``identical(caller_id, msg)`` is True when ``msg`` differs from the last one of
    ``caller_id``."""

    def __init__(self) -> None:
        self.last_logging_msg_table: Dict[Any, str] = {}

    def __call__(self, caller_id: Any, msg: str) -> bool:
        digest = hashlib.md5(str(msg).encode()).hexdigest()
        if self.last_logging_msg_table.get(caller_id) == digest:
            return False
        self.last_logging_msg_table[caller_id] = digest
        return True


class LoggingOnce:
    """``once(caller_id)`` is True the first time only."""

    def __init__(self) -> None:
        self.called_caller_ids: set = set()

    def __call__(self, caller_id: Any) -> bool:
        if caller_id in self.called_caller_ids:
            return False
        self.called_caller_ids.add(caller_id)
        return True


def get_ros_root(required: bool = False, env: Optional[Mapping[str, str]] = None) -> Optional[str]:
    """ROS_ROOT (normalised), None when unset; ROSException then if ``required``."""
    root = (os.environ if env is None else env).get("ROS_ROOT")
    root = os.path.normpath(root) if root else None
    if required and not root:
        raise ROSException("ROS_ROOT is not set")
    return root


def get_node_uri() -> Optional[str]:
    """This node's XML-RPC URI (None before init_node)."""
    return _node.default_node().uri


def set_node_uri(uri: str) -> None:
    """Record the node's URI (it does not move the node's server)."""
    _node.default_node().uri = uri


_log_filename: Optional[str] = None


def configure_logging(node_name: str, level: int = logging.INFO) -> None:
    """Log to the node's file in the ROS log directory (``__log:=`` overrides it), through
    rosgraph.roslogging's configuration."""
    global _log_filename
    mappings = _node.get_mappings()
    if "__log" in mappings:
        filename = os.path.abspath(mappings["__log"])
    else:
        filename = node_name.replace("/", "_") + ".log"
        if filename.startswith("_"):
            filename = filename[1:]
        if filename == ".log":
            raise ROSException(f"invalid configure_logging parameter: {node_name}")
    _log_filename = roslogging.configure_logging("rospy", level, filename=filename)


def is_initialized() -> bool:
    return _node.default_node().initialized


def set_initialized(initialized: bool) -> None:
    """Mark the node ready (rospy: names of new topics then resolve against the node)."""
    me = _node.default_node()
    me.lifecycle.initialized = initialized
    me.names.named = initialized or me.names.named


# ---------------------------------------------------------------------------------------------
# shutdown

_shutdown_lock = threading.RLock()
_shutdown_hooks: List[Callable[[str], Any]] = []
_preshutdown_hooks: List[Callable[[str], Any]] = []
_client_shutdown_hooks: List[Callable[[], Any]] = []
_shutdown_threads: List[threading.Thread] = []
_hooked_nodes: List[int] = []  # ids of the nodes whose shutdown runs these lists


def _run_hooks(hooks: List[Callable[..., Any]], *args: Any) -> None:
    with _shutdown_lock:
        todo = list(hooks)
        del hooks[:]
    for hook in todo:
        try:
            hook(*args)
        except Exception as exc:
            sys.stderr.write(f"signal_shutdown hook error[{exc}]\n")


def _hook_node() -> None:
    """Have the node's shutdown run rospy's hook lists (once per node)."""
    me = _node.default_node()
    with _shutdown_lock:
        if id(me) in _hooked_nodes:
            return
        _hooked_nodes.append(id(me))

    def before(_me: Any = me) -> None:  # a client hook: runs before the flag is set
        _run_hooks(_client_shutdown_hooks)
        _run_hooks(_preshutdown_hooks, "shutdown")

    def after(reason: str) -> None:  # an internal hook: runs once the flag is set
        _run_hooks(_shutdown_hooks, reason)
        _join_threads()

    me.on_shutdown(before)
    me.add_shutdown_hook(after)


def _join_threads() -> None:
    with _shutdown_lock:
        threads, _shutdown_threads[:] = list(_shutdown_threads), []
    for thread in threads:
        if thread.is_alive() and thread is not threading.current_thread():
            thread.join(_TIMEOUT_SHUTDOWN_JOIN)


def _add_shutdown_hook(hook: Any, hooks: List[Any], pass_reason_argument: bool = True) -> None:
    if not callable(hook):
        raise TypeError(f"shutdown hook [{hook}] must be a function or callable object: {type(hook)}")
    if _node.is_shutdown():
        _logger.warning("add_shutdown_hook called after shutdown")
        hook("already shutdown") if pass_reason_argument else hook()
        return
    _hook_node()
    with _shutdown_lock:
        hooks.append(hook)


def add_client_shutdown_hook(h: Callable[[], Any]) -> None:
    """``h()`` runs first at shutdown (rospy.on_shutdown's hooks)."""
    _add_shutdown_hook(h, _client_shutdown_hooks, pass_reason_argument=False)


def add_preshutdown_hook(h: Callable[[str], Any]) -> None:
    """``h(reason)`` runs at shutdown before the shutdown flag is set."""
    _add_shutdown_hook(h, _preshutdown_hooks)


def add_shutdown_hook(h: Callable[[str], Any]) -> None:
    """``h(reason)`` runs at shutdown once the flag is set; at once if already shut down."""
    _add_shutdown_hook(h, _shutdown_hooks)


def _add_shutdown_thread(t: threading.Thread) -> None:
    """A thread shutdown joins (bounded)."""
    if _node.is_shutdown():
        return
    _hook_node()
    with _shutdown_lock:
        _shutdown_threads[:] = [x for x in _shutdown_threads if x.is_alive()] + [t]


def is_shutdown() -> bool:
    return _node.is_shutdown()


def is_shutdown_requested() -> bool:
    return _node.is_shutdown_requested()


def signal_shutdown(reason: str) -> None:
    """Shut the node down (the hooks run in rospy's order)."""
    _logger.info("signal_shutdown [%s]", reason)
    if not _node.default_node().is_shutdown_requested():
        _hook_node()
    _node.signal_shutdown(reason)


def register_signals() -> None:
    """SIGINT and SIGTERM shut the node down (init_node does this unless told not to)."""
    from minros.client.init import _register_signals

    _register_signals()


def _reopen() -> None:
    """A fresh default node after a shutdown: rospy's tests reset ``_shutdown_flag`` to reuse
    the process. A node that ran (servers, registrations) is not reused that way."""
    old = _node.default_node()
    if not old.is_shutdown_requested():
        return
    fresh = _node.Node()
    # what rospy keeps in other globals than the shutdown flag survives, as there
    fresh.names.caller_id, fresh.names.named = old.names.caller_id, old.names.named
    fresh.names.argv_mappings = old.names.argv_mappings
    fresh.names.resolved_mappings = old.names.resolved_mappings
    fresh.lifecycle.initialized = old.lifecycle.initialized
    _node._default = fresh


# ---------------------------------------------------------------------------------------------
# validators and XML-RPC

def valid_name(param_name: str) -> Callable[[Any, str], Any]:
    """Validator: a graph name, resolved relative to the caller."""
    return _valid_name(param_name)


def is_topic(param_name: str) -> Callable[[Any, str], Any]:
    """Validator: a resolved topic name that is not the root namespace."""
    return _is_topic(param_name)


class _LockedServerProxy(xmlrpc.client.ServerProxy):
    """A ServerProxy shared between threads: one call at a time, each bounded in time."""

    def __init__(self, uri: str) -> None:
        super().__init__(uri, transport=_TimeoutTransport(XMLRPC_TIMEOUT))
        self._lock = threading.Lock()

    def _ServerProxy__request(self, methodname: str, params: Any) -> Any:  # noqa: N802
        with self._lock:
            # the name-mangled private method typeshed does not list
            return xmlrpc.client.ServerProxy._ServerProxy__request(  # type: ignore[attr-defined]
                self, methodname, params)


class _TimeoutTransport(xmlrpc.client.Transport):
    def __init__(self, timeout: float) -> None:
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host: Any) -> Any:
        conn = super().make_connection(host)
        conn.timeout = self._timeout
        return conn


_xmlrpc_cache: Dict[str, _LockedServerProxy] = {}
_xmlrpc_lock = threading.Lock()


def xmlrpcapi(uri: Optional[str], cache: bool = True) -> Optional[xmlrpc.client.ServerProxy]:
    """A proxy on ``uri`` (one per URI), or None when ``uri`` is not a URI."""
    if uri is None:
        return None
    parsed = urlparse(uri)
    if not parsed.scheme or not parsed.netloc:
        return None
    if not cache:
        return _LockedServerProxy(uri)
    with _xmlrpc_lock:
        if uri not in _xmlrpc_cache:
            _xmlrpc_cache[uri] = _LockedServerProxy(uri)
        return _xmlrpc_cache[uri]


# ---------------------------------------------------------------------------------------------
# rospy's module globals that are the node's state

class _CoreModule(types.ModuleType):
    @property
    def _shutdown_flag(self) -> bool:
        return _node.is_shutdown()

    @_shutdown_flag.setter
    def _shutdown_flag(self, value: bool) -> None:
        if not value:
            _reopen()

    @property
    def _in_shutdown(self) -> bool:
        return _node.is_shutdown_requested()

    @_in_shutdown.setter
    def _in_shutdown(self, value: bool) -> None:
        if not value:
            _reopen()

    @property
    def _uri(self) -> Optional[str]:
        return get_node_uri()

    @property
    def _client_ready(self) -> bool:
        return is_initialized()

    @property
    def Log(self) -> type:  # noqa: N802 - rospy.core's name for rosgraph_msgs/Log
        # generated on first use, so that importing rospy does not build the class
        from minros.msgs import get_message_class

        return get_message_class("rosgraph_msgs/Log")


sys.modules[__name__].__class__ = _CoreModule

#: what ``from rospy.core import *`` gives: rospy.core's public names
__all__ = [
    "ANYTYPE", "GLOBALNS", "Log", "LoggingIdentical", "LoggingOnce", "LoggingThrottle",  # noqa: F822 - Log: a property of the module
    "MASTER_NAME", "NullHandler", "ParameterInvalid", "REMAP", "ROSException",
    "ROSInitException", "ROSRPC", "SEP", "SERVICE_ANYTYPE", "TOPIC_ANYTYPE",
    "add_client_shutdown_hook", "add_preshutdown_hook", "add_shutdown_hook", "canonicalize_name",
    "configure_logging", "deprecated", "get_caller_id", "get_mappings", "get_name",
    "get_namespace", "get_node_uri", "get_resolved_mappings", "get_ros_namespace",
    "get_ros_root", "global_name", "initialize_mappings", "is_global", "is_initialized",
    "is_private", "is_shutdown", "is_shutdown_requested", "is_topic", "isstring",
    "load_mappings", "logdebug", "logdebug_once", "logdebug_throttle",
    "logdebug_throttle_identical", "logerr", "logerr_once", "logerr_throttle",
    "logerr_throttle_identical", "logerror", "logfatal", "logfatal_once", "logfatal_throttle",
    "logfatal_throttle_identical", "loginfo", "loginfo_once", "loginfo_throttle",
    "loginfo_throttle_identical", "logout", "logwarn", "logwarn_once", "logwarn_throttle",
    "logwarn_throttle_identical", "make_global_ns", "namespace", "ns_join", "parse_rosrpc_uri",
    "register_signals", "reload_mappings", "remap_name", "resolve_name",
    "resolve_name_without_node_name", "rospydebug", "rospyerr", "rospyinfo", "rospywarn",
    "scoped_name", "set_initialized", "set_node_uri", "signal_shutdown", "valid_name",
    "valid_name_validator_resolved", "valid_name_validator_unresolved", "xmlrpcapi",
]


def star_import(target: Dict[str, Any]) -> None:
    """``from rospy.core import *`` into ``target`` (a module's globals), as rospy's own
    modules do, except ``Log``: that one the module serves through the ``__getattr__`` this
    puts there, so the message class is built on first use only."""
    module = sys.modules[__name__]
    for name in __all__:
        if name != "Log":
            target[name] = getattr(module, name)
    previous = target.get("__getattr__")

    def __getattr__(name: str) -> Any:  # noqa: N807 - a module's attribute hook
        if name == "Log":
            return module.Log
        if previous is not None:
            return previous(name)
        raise AttributeError(f"module {target.get('__name__')!r} has no attribute {name!r}")

    target["__getattr__"] = __getattr__
