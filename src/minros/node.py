"""Node runtime: name and arguments, the slave XML-RPC API, master registration, the one
TCPROS server per process, and the lifecycle (init, shutdown hooks, signals).

Topics (``minros.client.topics``) and services (``minros.client.services``) register their endpoints here,
so that everything a node offers is (re-)registered in one place: on ``init_node``, after a
master restart, and undone with one ``system.multicall`` on shutdown.
"""

from __future__ import annotations

import atexit
import logging
import os
import signal
import socket
import struct
import sys
import threading
import time
import traceback
import urllib.parse
from typing import Any, Callable, Dict, List, Tuple

from minros import names, rosenv
from minros.exceptions import ROSException, ROSInitException, ServiceException
from minros.wire import tcpros
from minros.wire import xmlrpc as minros_xmlrpc
from minros.wire.xmlrpc import ServerProxy, XmlRpcServer

__all__ = [
    "DEFAULT_MASTER_URI",
    "MasterProxy",
    "Node",
    "add_param_update_handler",
    "get_caller_id",
    "get_master",
    "get_master_proxy",
    "get_mappings",
    "get_master_uri",
    "get_name",
    "get_namespace",
    "get_node",
    "get_node_uri",
    "get_tcpros_address",
    "init_node",
    "is_initialized",
    "is_shutdown",
    "is_shutdown_requested",
    "myargv",
    "on_shutdown",
    "register_service",
    "remap_name",
    "resolve_name",
    "signal_shutdown",
    "spin",
    "subscribe_param",
    "unregister_service",
    "wait_for_shutdown",
]

DEFAULT_MASTER_URI = rosenv.DEFAULT_MASTER_URI
#: how often the master is probed to notice that it restarted
MASTER_PROBE_INTERVAL = 1.0
#: time allowed to read an inbound connection header
HEADER_TIMEOUT = 10.0
#: timeout of XML-RPC calls to the master and to other nodes
XMLRPC_TIMEOUT = 10.0

_logger = logging.getLogger("minros.node")

# ---------------------------------------------------------------------------------------------
# process-wide state (a process is at most one node, as in rospy)

_state_lock = threading.RLock()
_node: Node | None = None
_init_args: tuple | None = None
_shutdown_event = threading.Event()  # set once shutdown is complete enough for is_shutdown()
_shutdown_requested = False
_shutdown_thread: threading.Thread | None = None
_shutdown_done = threading.Event()  # set when the shutdown sequence has finished
_client_hooks: List[Callable[[], Any]] = []
_internal_hooks: List[Callable[[str], Any]] = []
_argv_mappings: Dict[str, str] = names.load_mappings(sys.argv)
_resolved_mappings: Dict[str, str] = {}
_caller_id = names.get_ros_namespace(argv=sys.argv) + "unnamed"
_signal_chain: Dict[int, Any] = {}
_init_argv: List[str] | None = None
_initialized = False

# registries filled by minros.client.topics / minros.client.services, registered with the master on init
_publications: Dict[str, Any] = {}  # resolved topic -> publisher impl (.type, .md5sum, ...)
_subscriptions: Dict[str, Any] = {}  # resolved topic -> subscriber impl
_services: Dict[str, Callable] = {}  # resolved service -> handler(sock, header)
_param_subscriptions: Dict[str, Any] = {}  # resolved key -> last value
_param_update_handlers: List[Callable[[str, Any], bool]] = []
_registry_lock = threading.RLock()


# ---------------------------------------------------------------------------------------------
# names


def get_caller_id() -> str:
    """The node's global name ('/unnamed' in its namespace before init_node)."""
    return _caller_id


get_name = get_caller_id


def get_namespace() -> str:
    """The node's namespace with trailing '/'."""
    return names.namespace(_caller_id)


def get_mappings() -> Dict[str, str]:
    """Command-line remappings (as given, unresolved; ``__name`` etc. included)."""
    return dict(_argv_mappings)


def resolve_name(name: str, caller_id: str | None = None) -> str:
    """Resolve ``name`` relative to the node (or ``caller_id``), applying remappings."""
    if caller_id is None:
        caller_id = _caller_id
    if not name:
        return names.namespace(caller_id)
    resolved = names.resolve_name(name, caller_id)
    mappings = _resolved_mappings if caller_id == _caller_id else names.resolve_mappings(
        {k: v for k, v in _argv_mappings.items() if not k.startswith("__")}, caller_id)
    return mappings.get(resolved, resolved)


def resolve_name_without_node_name(name: str) -> str:
    """Resolve a topic/service name created before init_node (rospy semantics): relative to
    the namespace, with the command-line remappings; ``~name`` is an error then."""
    if names.is_private(name):
        raise ValueError("~name topics cannot be created before init_node() has been called")
    fake_caller_id = names.ns_join(names.get_ros_namespace(argv=sys.argv), "node")
    resolved = names.resolve_name(name, fake_caller_id)
    for src, dst in _argv_mappings.items():
        if src.startswith("__"):
            continue
        if names.resolve_name(src, fake_caller_id) == resolved:
            if names.is_private(dst):
                raise ROSInitException(
                    f"due to the way this node is written, {name} cannot be remapped to a ~name. \n"
                    "The declaration of topics/services must be moved after the call to init_node()")
            return names.resolve_name(dst, fake_caller_id)
    return resolved


def remap_name(name: str, caller_id: str | None = None, resolved: bool = True) -> str:
    """Remap ``name`` without otherwise resolving it (rospy.remap_name)."""
    if caller_id is None:
        caller_id = _caller_id
    if name in _argv_mappings:
        return names.resolve_name(_argv_mappings[name], caller_id)
    return name


def myargv(argv: List[str] | None = None) -> List[str]:
    """``argv`` (default sys.argv) without remapping arguments."""
    if argv is None:
        argv = sys.argv
    return names.strip_remapping_args(argv)


# ---------------------------------------------------------------------------------------------
# network configuration (rosgraph.network semantics)


def get_host_name() -> str:
    """The host name this node advertises in its URIs (``__hostname``/``__ip``, ROS_HOSTNAME,
    ROS_IP, else the machine's name)."""
    return minros_xmlrpc.get_host_name() if _init_argv is None else _host_from(_init_argv)


def _host_from(argv: List[str]) -> str:
    override = minros_xmlrpc.get_address_override(argv=argv)
    return override if override else minros_xmlrpc.get_host_name()


def get_bind_address() -> str:
    """Loopback when the advertised address is loopback, else every interface."""
    argv = sys.argv if _init_argv is None else _init_argv
    return minros_xmlrpc.get_bind_address(minros_xmlrpc.get_address_override(argv=argv))


def _default_master_uri() -> str:
    return rosenv.get_master_uri(remapped=_argv_mappings.get("__master"))


# ---------------------------------------------------------------------------------------------
# lifecycle


def get_node() -> Node | None:
    return _node


def is_initialized() -> bool:
    """True once init_node has registered the node (publishing is allowed from then on)."""
    return _initialized


def is_shutdown() -> bool:
    return _shutdown_event.is_set()


def is_shutdown_requested() -> bool:
    return _shutdown_requested or _shutdown_event.is_set()


def wait_for_shutdown(timeout: float | None) -> bool:
    """Block up to ``timeout`` seconds; True if the node is (or becomes) shut down."""
    return _shutdown_event.wait(timeout)


def on_shutdown(hook: Callable[[], Any]) -> None:
    """Call ``hook()`` when the node shuts down, before it unregisters from the master."""
    with _state_lock:
        if _shutdown_event.is_set():
            run_now = True
        else:
            _client_hooks.append(hook)
            run_now = False
    if run_now:
        hook()


def add_shutdown_hook(hook: Callable[[str], Any]) -> None:
    """Internal: ``hook(reason)`` runs during shutdown after the client hooks."""
    with _state_lock:
        _internal_hooks.append(hook)


def signal_shutdown(reason: str) -> None:
    """Shut the node down: client hooks, one unregistration multicall, close transports."""
    global _shutdown_requested, _shutdown_thread
    with _state_lock:
        if _shutdown_requested:
            in_progress_here = _shutdown_thread is threading.current_thread()
            first = False
        else:
            _shutdown_requested = True
            _shutdown_thread = threading.current_thread()
            first = True
            client_hooks = list(_client_hooks)
            del _client_hooks[:]
    if not first:
        # e.g. atexit while a shutdown started by `rosnode kill` is still unregistering:
        # let it finish, so the process does not exit halfway through the multicall
        if not in_progress_here:
            _shutdown_done.wait(5.0)
        return
    try:
        _do_shutdown(reason, client_hooks)
    finally:
        _shutdown_done.set()


def _do_shutdown(reason: str, client_hooks: List[Callable[[], Any]]) -> None:
    _logger.info("signal_shutdown [%s]", reason)
    for hook in client_hooks:
        try:
            hook()
        except Exception:
            traceback.print_exc()
    _shutdown_event.set()
    with _state_lock:
        internal = list(_internal_hooks)
        del _internal_hooks[:]
    for hook in internal:
        try:
            hook(reason)
        except Exception as exc:
            sys.stderr.write(f"signal_shutdown hook error[{exc}]\n")
    node = _node
    if node is not None:
        node.shutdown(reason)


def _on_signal(signum, frame) -> None:
    signal_shutdown(f"signal-{signum}")
    previous = _signal_chain.get(signum)
    if callable(previous) and previous is not signal.default_int_handler:
        try:
            previous(signum, frame)
        except KeyboardInterrupt:
            pass


def _register_signals() -> None:
    if threading.current_thread() is not threading.main_thread():
        return
    for signum in (signal.SIGINT, signal.SIGTERM):
        try:
            _signal_chain[signum] = signal.signal(signum, _on_signal)
        except (ValueError, OSError):  # not the main interpreter
            pass


atexit.register(lambda: signal_shutdown("atexit"))


def spin() -> None:
    """Block until the node is shut down."""
    if not _initialized:
        raise ROSInitException("client code must call rospy.init_node() first")
    try:
        while not _shutdown_event.wait(0.5):
            pass
    except KeyboardInterrupt:
        signal_shutdown("keyboard interrupt")


# ---------------------------------------------------------------------------------------------
# init_node


def init_node(name: str, argv: List[str] | None = None, anonymous: bool = False,
              log_level: int | None = None, disable_rostime: bool = False,
              disable_rosout: bool = False, disable_signals: bool = False,
              xmlrpc_port: int = 0, tcpros_port: int = 0) -> None:
    """Register this process as the node ``name`` with the master (rospy.init_node)."""
    global _node, _init_args, _caller_id, _argv_mappings, _resolved_mappings, _init_argv
    global _initialized
    if argv is None:
        argv = sys.argv
    else:
        _argv_mappings = names.load_mappings(argv)
    if not name:
        raise ValueError("name must not be empty")
    if names.SEP in name:
        raise ValueError("namespaces are not allowed in node names")
    args = (name, list(argv), anonymous, log_level, disable_rostime, disable_signals)
    with _state_lock:
        if _init_args is not None:
            if _init_args != args:
                raise ROSException(
                    "rospy.init_node() has already been called with different arguments: "
                    + str(_init_args))
            return
        _init_args = args
    _init_argv = list(argv)
    if not disable_signals:
        _register_signals()
    if "__name" in _argv_mappings:
        name = _argv_mappings["__name"]
        anonymous = False
    if anonymous:
        name = f"{name}_{os.getpid()}_{int(time.time() * 1000)}"
    if not names.is_legal_base_name(name):
        import warnings

        warnings.warn(f"'{name}' is not a legal ROS base name. This may cause problems with "
                      "other ROS tools.", stacklevel=2)
    namespace = names.get_ros_namespace(argv=argv)
    caller_id = names.resolve_name(name, namespace + "unnamed")
    _caller_id = caller_id
    _resolved_mappings = names.resolve_mappings(
        {k: v for k, v in _argv_mappings.items() if not k.startswith("__")}, caller_id)

    node = Node(caller_id, _default_master_uri(), xmlrpc_port=xmlrpc_port, tcpros_port=tcpros_port)
    _node = node
    node.start()
    if is_shutdown_requested():
        raise ROSInitException("init_node interrupted before it could complete")

    # private parameters from the command line (_name:=value, YAML-typed)
    try:
        params = names.load_command_line_node_params(argv)
    except ValueError as exc:
        raise ROSInitException(str(exc)) from None
    for key, value in params.items():
        node.master_call("setParam", names.ns_join(caller_id, key), value)

    _initialized = True  # as rospy: before /rosout and /clock are set up
    use_sim_time = False
    if not disable_rostime:
        try:
            code, _msg, value = node.master_call("getParam", "/use_sim_time")
            use_sim_time = code == 1 and bool(value)
        except Exception:
            use_sim_time = False
    try:
        from minros.client import rostime

        starter = getattr(rostime, "_start_node_time", None)
        if starter is not None:
            starter(use_sim_time and not disable_rostime)
    except ImportError:
        pass
    try:
        from minros.client import log

        starter = getattr(log, "_start_node_logging", None)
        if starter is not None:
            starter(caller_id, log_level, disable_rosout)
    except ImportError:
        pass


def get_master_uri() -> str:
    node = _node
    return node.master_uri if node is not None else _default_master_uri()


def get_node_uri() -> str | None:
    node = _node
    return node.uri if node is not None else None


def get_tcpros_address() -> Tuple[str, int]:
    """(advertised host, port) of this process's TCPROS server (started on first use)."""
    node = _node
    if node is None:
        raise ROSInitException("client code must call rospy.init_node() first")
    return node.tcpros_address()


def get_master_proxy(timeout: float = XMLRPC_TIMEOUT) -> ServerProxy:
    """An XML-RPC proxy to the master (callable before init_node)."""
    return ServerProxy(get_master_uri(), timeout=timeout)


def master_call(method: str, *args: Any) -> list:
    """``master.method(caller_id, *args)`` returning the raw triplet (works before init_node)."""
    node = _node
    if node is not None:
        return node.master_call(method, *args)
    return master_call_once(method, *args)


def master_call_once(method: str, *args: Any) -> list:
    """``master.method(caller_id, *args)`` on a fresh connection, closed afterwards; OSError
    when the master is unreachable."""
    proxy = get_master_proxy()
    try:
        return getattr(proxy, method)(_caller_id, *args)
    finally:
        proxy.close()


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
        self.target = ServerProxy(uri, timeout=XMLRPC_TIMEOUT)

    def __getattr__(self, key: str) -> Callable[..., Any]:
        if key.startswith("__"):
            raise AttributeError(key)
        remap = _MASTER_ARG_REMAP.get(key, [])

        def call(*args: Any) -> Any:
            full = [get_caller_id(), *args]
            for i in remap:
                if i + 1 < len(full):
                    full[i + 1] = resolve_name(full[i + 1])
            return getattr(self.target, key)(*full)

        return call

    def __getitem__(self, key: str) -> Any:
        code, _msg, value = self.target.getParam(get_caller_id(), resolve_name(key))
        if code != 1:
            raise KeyError(key)
        return value

    def __setitem__(self, key: str, value: Any) -> None:
        self.target.setParam(get_caller_id(), resolve_name(key), value)

    def __delitem__(self, key: str) -> None:
        code, msg, _ = self.target.deleteParam(get_caller_id(), resolve_name(key))
        if code == -1:
            raise KeyError(key)
        if code != 1:
            raise ROSException(f"cannot delete parameter: {msg}")

    def __contains__(self, key: str) -> bool:
        code, msg, value = self.target.hasParam(get_caller_id(), resolve_name(key))
        if code != 1:
            raise ROSException(f"cannot check parameter on server: {msg}")
        return bool(value)

    def __iter__(self):
        code, msg, value = self.target.getParamNames(get_caller_id())
        if code != 1:
            raise ROSException(f"cannot retrieve parameter names: {msg}")
        return iter(value)

    def search_param(self, key: str) -> str | None:
        key = _argv_mappings.get(key, key)
        code, msg, value = self.target.searchParam(get_caller_id(), key)
        if code == 1:
            return value
        if code == -1:
            return None
        raise ROSException(f"cannot search for parameter: {msg}")

    def get_param_cached(self, key: str) -> Any:
        from minros.client import params

        return params.get_param_cached(key)


def get_master(env: Dict[str, str] | None = None) -> MasterProxy:
    """A MasterProxy for ROS_MASTER_URI (or ``env``'s)."""
    if env is not None and env is not os.environ:
        uri = rosenv.get_master_uri(env)
    else:
        uri = get_master_uri()
    return MasterProxy(uri)


# ---------------------------------------------------------------------------------------------
# registries used by topics/services/params


def _add_publication(impl: Any) -> None:
    with _registry_lock:
        _publications[impl.resolved_name] = impl
    node = _node
    if node is not None:
        node.register("pub", impl.resolved_name, impl.type)


def _remove_publication(impl: Any) -> None:
    with _registry_lock:
        if _publications.get(impl.resolved_name) is impl:
            del _publications[impl.resolved_name]
    node = _node
    if node is not None and not is_shutdown_requested():
        node.unregister("pub", impl.resolved_name)


def _add_subscription(impl: Any) -> None:
    with _registry_lock:
        _subscriptions[impl.resolved_name] = impl
    node = _node
    if node is not None:
        node.register("sub", impl.resolved_name, impl.type)


def _remove_subscription(impl: Any) -> None:
    with _registry_lock:
        if _subscriptions.get(impl.resolved_name) is impl:
            del _subscriptions[impl.resolved_name]
    node = _node
    if node is not None and not is_shutdown_requested():
        node.unregister("sub", impl.resolved_name)


def _get_publication(resolved_name: str) -> Any:
    return _publications.get(resolved_name)


def _get_subscription(resolved_name: str) -> Any:
    return _subscriptions.get(resolved_name)


def register_service(resolved_name: str, handler: Callable[[socket.socket, Dict[str, str]], Any]) -> None:
    """Serve ``resolved_name`` on this process's TCPROS server and register it with the master.

    ``handler(sock, header)`` runs in the connection's thread for inbound connections whose
    header names this service; it owns the socket from then on. ServiceException if this
    process already serves ``resolved_name`` (checked under the registry lock: no two winners).
    """
    with _registry_lock:
        if resolved_name in _services:
            raise ServiceException(f"service [{resolved_name}] already registered")
        _services[resolved_name] = handler
    node = _node
    if node is not None:
        node.register("srv", resolved_name, None)


def unregister_service(resolved_name: str) -> None:
    with _registry_lock:
        _services.pop(resolved_name, None)
    node = _node
    if node is not None and not is_shutdown_requested():
        node.unregister("srv", resolved_name)


def subscribe_param(resolved_key: str) -> Any:
    """subscribeParam with the master; later paramUpdate calls go to the handlers. Returns
    the current value (``{}`` when unset, as the master answers)."""
    node = _node
    if node is None:
        raise ROSInitException("client code must call rospy.init_node() first")
    with _registry_lock:
        _param_subscriptions[resolved_key] = None
    code, msg, value = node.master_call("subscribeParam", node.uri, resolved_key)
    if code != 1:
        raise ROSException(f"cannot subscribe to parameter [{resolved_key}]: {msg}")
    return value


def unsubscribe_param(resolved_key: str) -> None:
    with _registry_lock:
        _param_subscriptions.pop(resolved_key, None)
    node = _node
    if node is not None:
        try:
            node.master_call("unsubscribeParam", node.uri, resolved_key)
        except Exception:
            pass


def add_param_update_handler(handler: Callable[[str, Any], bool]) -> None:
    """``handler(key, value) -> bool`` is called for every slave paramUpdate."""
    _param_update_handlers.append(handler)


# ---------------------------------------------------------------------------------------------
# slave API


class _ApiError(Exception):
    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


def _slave_api(error_value: Any, nargs: int):
    """Decorate a slave method: caller_id and arity checks, errors as [code, msg, value]."""

    def wrap(fn):
        def method(self, *args):
            if not args:
                return [-1, "missing required caller_id parameter", error_value]
            if len(args) != nargs + 1:
                return [-1, "Error: bad call arity", error_value]
            if not isinstance(args[0], str):
                return [-1, "caller_id must be a string", error_value]
            try:
                code, msg, value = fn(self, *args)
            except _ApiError as exc:
                return [-1, exc.message, error_value]
            except Exception as exc:
                _logger.error("slave API %s failed: %s", fn.__name__, traceback.format_exc())
                return [0, f"Internal failure: {exc}", error_value]
            if value is None:
                return [-1, "Internal error (None value returned)", error_value]
            return [code, msg, value]

        method.__name__ = fn.__name__
        method.__doc__ = fn.__doc__
        return method

    return wrap


def _valid_topic(param: str, value: Any, caller_id: str) -> str:
    if not value or not isinstance(value, str):
        raise _ApiError(f"ERROR: parameter [{param}] must be a non-empty string")
    if ":" in value or " " in value:
        raise _ApiError(f"ERROR: parameter [{param}] contains illegal chars")
    if value == "/":
        raise _ApiError(f"ERROR: parameter [{param}] cannot be the global namespace")
    return names.resolve_name(value, caller_id)


_INT32_MAX = (1 << 31) - 1


def _xmlrpc_ints(value: Any) -> Any:
    """Byte counters of a long-lived connection outgrow XML-RPC's 32-bit int: saturate them."""
    if isinstance(value, list):
        return [_xmlrpc_ints(v) for v in value]
    if isinstance(value, int) and not isinstance(value, bool) and value > _INT32_MAX:
        return _INT32_MAX
    return value


class SlaveApi:
    """The node's XML-RPC API (methods are called by the master, tools and other nodes)."""

    def __init__(self, node: Node) -> None:
        self._node = node

    @_slave_api("", 0)
    def getUri(self, caller_id):
        return 1, "", self._node.uri

    @_slave_api("", 0)
    def getName(self, caller_id):
        return 1, "", self._node.name

    @_slave_api([], 0)
    def getBusStats(self, caller_id):
        with _registry_lock:
            pubs = [impl.get_stats() for impl in _publications.values()]
            subs = [impl.get_stats() for impl in _subscriptions.values()]
        return 1, "", _xmlrpc_ints([pubs, subs, []])

    @_slave_api([], 0)
    def getBusInfo(self, caller_id):
        info: list = []
        with _registry_lock:
            impls = list(_publications.values()) + list(_subscriptions.values())
        for impl in impls:
            info.extend(impl.get_stats_info())
        return 1, "bus info", info

    @_slave_api("", 0)
    def getMasterUri(self, caller_id):
        uri = self._node.master_uri
        if uri:
            return 1, uri, uri
        return 0, "master URI not set", ""

    @_slave_api(0, 1)
    def shutdown(self, caller_id, msg=""):
        if msg:
            print(f"shutdown request: {msg}", flush=True)
        else:
            print("shutdown requst", flush=True)
        reason = f"external shutdown request from [{caller_id}]: [{msg}]"
        # the reply must leave before the servers close: shut down from another thread
        self._node._reply_grace = 0.2
        threading.Thread(target=signal_shutdown, args=(reason,), daemon=True).start()
        return 1, "shutdown", 0

    @_slave_api(-1, 0)
    def getPid(self, caller_id):
        return 1, "", os.getpid()

    @_slave_api([], 0)
    def getSubscriptions(self, caller_id):
        with _registry_lock:
            return 1, "subscriptions", [[t, impl.type] for t, impl in _subscriptions.items()]

    @_slave_api([], 0)
    def getPublications(self, caller_id):
        with _registry_lock:
            return 1, "publications", [[t, impl.type] for t, impl in _publications.items()]

    @_slave_api(-1, 2)
    def paramUpdate(self, caller_id, key, value):
        if not key or not isinstance(key, str):
            raise _ApiError("ERROR: parameter [parameter_key] must be a non-empty string")
        if not names.is_global(key):
            raise _ApiError("ERROR: parameter [parameter_key] must be a globally referenced name")
        cached = False
        for handler in list(_param_update_handlers):
            try:
                cached = bool(handler(key, value)) or cached
            except Exception:
                _logger.error("paramUpdate handler failed: %s", traceback.format_exc())
        if not cached:
            with _registry_lock:
                wanted = [k for k in _param_subscriptions
                          if k == key or k.startswith(key.rstrip("/") + "/")
                          or key.startswith(k.rstrip("/") + "/")]
                for k in wanted:
                    _param_subscriptions[k] = value
            cached = bool(wanted)
        if not cached:
            return -1, "not subscribed", 0
        return 1, "", 0

    @_slave_api(-1, 2)
    def publisherUpdate(self, caller_id, topic, publishers):
        topic = _valid_topic("topic", topic, caller_id)
        if not isinstance(publishers, list):
            raise _ApiError("ERROR: param [publishers] must be a list")
        for uri in publishers:
            if not isinstance(uri, str):
                raise _ApiError("ERROR: param [publishers] must be a list of strings")
            parsed = urllib.parse.urlparse(uri)
            if not parsed.scheme or not parsed.netloc:
                raise _ApiError(f"ERROR: param [publishers] does not contain valid URLs [{uri}]")
        impl = _subscriptions.get(topic)
        if impl is not None:
            impl.publisher_update(publishers)
        return 1, "", 0

    @_slave_api([], 2)
    def requestTopic(self, caller_id, topic, protocols):
        topic = _valid_topic("topic", topic, caller_id)
        if not protocols:
            raise _ApiError("ERROR: parameter [protocols] must be specified and non-empty")
        if not isinstance(protocols, list):
            raise _ApiError("ERROR: parameter [protocols] must be a list of protocols")
        if topic not in _publications:
            return -1, f"Not a publisher of [{topic}]", []
        for protocol in protocols:
            if isinstance(protocol, list) and protocol and protocol[0] == tcpros.TCPROS:
                host, port = self._node.tcpros_address()
                return 1, f"ready on {host}:{port}", [tcpros.TCPROS, host, port]
        return 0, "no supported protocol implementations", []


# ---------------------------------------------------------------------------------------------
# the node


def _recv_header_bytes(sock: socket.socket, size: int) -> bytes:
    buf = bytearray(size)
    view = memoryview(buf)
    got = 0
    while got < size:
        try:
            n = sock.recv_into(view[got:])
        except socket.timeout:
            raise tcpros.HeaderError("timed out waiting for the connection header") from None
        except OSError as exc:
            raise tcpros.HeaderError(f"unable to receive the connection header: {exc}") from None
        if not n:
            raise tcpros.HeaderError(f"connection closed after {got} of {size} header bytes")
        got += n
    return bytes(buf)


def read_inbound_header(sock: socket.socket, max_size: int = tcpros.DEFAULT_MAX_HEADER) -> Dict[str, str]:
    """Read exactly one connection header from ``sock`` (nothing beyond it), for both sides of
    a topic or service handshake. The socket's timeout bounds every read; every failure is a
    HeaderError naming it."""
    (size,) = struct.unpack("<I", _recv_header_bytes(sock, 4))
    if size > max_size:
        raise tcpros.HeaderError(f"connection header of {size} bytes exceeds the limit of {max_size}")
    return tcpros.decode_header(_recv_header_bytes(sock, size))


def _user_warn(text: str) -> None:
    """A WARN line on the node's console and /rosout, as rospy's logwarn."""
    try:
        from minros.client import log

        log.logwarn(text)
    except Exception:
        _logger.warning(text)


def _user_error(text: str) -> None:
    """An ERROR line on the node's console (rospy's logerr)."""
    try:
        from minros.client import log

        log.logerr(text)
    except Exception:
        sys.stderr.write(text + "\n")


class Node:
    """The servers and master registrations of this process."""

    def __init__(self, name: str, master_uri: str, xmlrpc_port: int = 0, tcpros_port: int = 0) -> None:
        self.name = name
        self.master_uri = master_uri
        self.host = get_host_name()
        self._xmlrpc_port = xmlrpc_port
        self._tcpros_port = tcpros_port
        self._tcpros_sock: socket.socket | None = None
        self._tcpros_lock = threading.Lock()
        self._xmlrpc: XmlRpcServer | None = None
        self.uri: str | None = None
        self._local = threading.local()
        self._reg_lock = threading.RLock()
        self._master_pid: int | None = None
        self._master_lost = False
        self._done = threading.Event()
        self._inbound: set = set()
        self._warned_master = False
        self._reply_grace = 0.0

    # -- XML-RPC -----------------------------------------------------------------------------

    def master(self) -> ServerProxy:
        proxy = getattr(self._local, "master", None)
        if proxy is None:
            proxy = ServerProxy(self.master_uri, timeout=XMLRPC_TIMEOUT)
            self._local.master = proxy
        return proxy

    def master_call(self, method: str, *args: Any) -> list:
        try:
            return getattr(self.master(), method)(self.name, *args)
        except Exception:
            self._local.master = None
            raise

    # -- servers -----------------------------------------------------------------------------

    def start(self) -> None:
        self._xmlrpc = XmlRpcServer(SlaveApi(self), host=get_bind_address(), port=self._xmlrpc_port)
        self._xmlrpc.start()
        self.uri = f"http://{self.host}:{self._xmlrpc.port}/"
        _logger.info("ROS Slave URI: [%s]", self.uri)
        if self._tcpros_port:
            self.tcpros_address()
        self._register_all(first=True)
        threading.Thread(target=self._monitor_master, name="minros-master-probe", daemon=True).start()

    def tcpros_address(self) -> Tuple[str, int]:
        with self._tcpros_lock:
            if self._tcpros_sock is None:
                server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
                server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                server.bind((get_bind_address(), self._tcpros_port))
                server.listen(128)
                self._tcpros_sock = server
                threading.Thread(target=self._accept_loop, args=(server,),
                                 name="minros-tcpros-server", daemon=True).start()
            return self.host, self._tcpros_sock.getsockname()[1]

    def _accept_loop(self, server: socket.socket) -> None:
        while not self._done.is_set():
            try:
                sock, addr = server.accept()
            except OSError:
                if self._done.is_set():
                    return
                time.sleep(0.01)
                continue
            threading.Thread(target=self._handle_inbound, args=(sock, addr),
                             name="minros-tcpros-inbound", daemon=True).start()

    def _handle_inbound(self, sock: socket.socket, addr) -> None:
        """Read the connection header and hand the socket to the topic or service."""
        try:
            sock.settimeout(HEADER_TIMEOUT)
            header = read_inbound_header(sock)
            sock.settimeout(None)
        except (OSError, tcpros.HeaderError) as exc:
            if not is_shutdown_requested():
                _user_warn(f"Inbound TCP/IP connection failed: {exc}")
            _close(sock)
            return
        try:
            if "topic" in header:
                impl = _publications.get(header["topic"])
                error = None
                if is_shutdown_requested():
                    error = "Node is shutting down"
                elif impl is None:
                    error = tcpros.publisher_header_error(header, self.name, {
                        t: (p.type, p.md5sum) for t, p in list(_publications.items())})
                if error is None:
                    error = impl.accept_subscriber(sock, addr, header)
            elif "service" in header:
                handler = _services.get(header["service"])
                if handler is None:
                    error = f"[{self.name}] is not a provider of [{header['service']}]"
                else:
                    handler(sock, header)
                    return
            else:
                error = "no topic or service name detected"
        except Exception as exc:
            error = f"internal error: {exc}"
            _logger.error("inbound connection failed: %s", traceback.format_exc())
        if error is not None:
            if is_shutdown_requested():
                error = "node shutting down"
            else:  # rospy's wording, header dict included
                _user_warn(f"Could not process inbound connection: {error}{header}")
            try:
                sock.sendall(tcpros.encode_error_header(error))
            except OSError:
                pass
            _close(sock)

    # -- registration ------------------------------------------------------------------------

    def register(self, kind: str, name: str, type_: str | None) -> None:
        """Register one endpoint; on a master failure the probe thread redoes it later."""
        try:
            with self._reg_lock:
                self._register_one(kind, name, type_)
        except Exception as exc:
            self._master_lost = True
            _logger.warning("cannot register %s [%s] with the master now (%s); will retry",
                            kind, name, exc)

    def _register_one(self, kind: str, name: str, type_: str | None) -> None:
        if kind == "pub":
            code, msg, _ = self.master_call("registerPublisher", name, type_, self.uri)
        elif kind == "sub":
            code, msg, pubs = self.master_call("registerSubscriber", name, type_, self.uri)
            if code == 1:
                impl = _subscriptions.get(name)
                if impl is not None:
                    impl.publisher_update(pubs)
        elif kind == "srv":
            host, port = self.tcpros_address()
            code, msg, _ = self.master_call("registerService", name, f"rosrpc://{host}:{port}", self.uri)
        else:  # param
            code, msg, value = self.master_call("subscribeParam", self.uri, name)
            if code == 1:
                for handler in list(_param_update_handlers):
                    try:
                        handler(name, value)
                    except Exception:
                        pass
        if code != 1:
            _logger.error("master refused to register %s [%s]: %s", kind, name, msg)

    def unregister(self, kind: str, name: str) -> None:
        try:
            if kind == "pub":
                self.master_call("unregisterPublisher", name, self.uri)
            elif kind == "sub":
                self.master_call("unregisterSubscriber", name, self.uri)
            elif kind == "srv":
                host, port = self.tcpros_address()
                self.master_call("unregisterService", name, f"rosrpc://{host}:{port}")
        except Exception as exc:
            _logger.warning("cannot unregister %s [%s]: %s", kind, name, exc)

    def _register_all(self, first: bool = False) -> None:
        """Register every publication, subscription, service and parameter subscription,
        retrying every 0.2 s until the master answers."""
        while not is_shutdown_requested():
            try:
                with self._reg_lock:
                    code, _msg, pid = self.master_call("getPid")
                    with _registry_lock:
                        pubs = [(t, p.type) for t, p in _publications.items()]
                        subs = [(t, s.type) for t, s in _subscriptions.items()]
                        srvs = list(_services)
                        params = list(_param_subscriptions)
                    for topic, type_ in pubs:
                        self._register_one("pub", topic, type_)
                    for topic, type_ in subs:
                        self._register_one("sub", topic, type_)
                    for service in srvs:
                        self._register_one("srv", service, None)
                    for key in params:
                        self._register_one("param", key, None)
                    self._master_pid = pid if code == 1 else None
                    self._master_lost = False
                    if not first:
                        _logger.info("re-registered with the master at %s", self.master_uri)
                return
            except Exception as exc:
                if not self._warned_master:
                    self._warned_master = True
                    text = (f"Unable to immediately register with master node [{self.master_uri}]: "
                            "master may not be running yet. Will keep trying.")
                    if first:
                        _user_error(text)
                    else:
                        _logger.error(text)
                _logger.debug("registration failed: %s", exc)
                if _shutdown_event.wait(0.2):
                    return

    def _monitor_master(self) -> None:
        """Probe the master every second; re-register after it restarted or came back."""
        proxy = ServerProxy(self.master_uri, timeout=2.0)
        while not _shutdown_event.wait(MASTER_PROBE_INTERVAL):
            if self._done.is_set():
                return
            try:
                code, _msg, pid = proxy.getPid(self.name)
            except Exception:
                proxy = ServerProxy(self.master_uri, timeout=2.0)
                if not self._master_lost:
                    _logger.warning("lost contact with the master at %s", self.master_uri)
                self._master_lost = True
                continue
            if self._master_lost or (code == 1 and pid != self._master_pid):
                self._warned_master = True
                self._register_all()

    # -- shutdown ----------------------------------------------------------------------------

    def shutdown(self, reason: str) -> None:
        if self._done.is_set():
            return
        self._done.set()
        calls = []
        with _registry_lock:
            for topic in _subscriptions:
                calls.append({"methodName": "unregisterSubscriber", "params": [self.name, topic, self.uri]})
            for topic in _publications:
                calls.append({"methodName": "unregisterPublisher", "params": [self.name, topic, self.uri]})
            if _services and self._tcpros_sock is not None:
                host, port = self.host, self._tcpros_sock.getsockname()[1]
                for service in _services:
                    calls.append({"methodName": "unregisterService",
                                  "params": [self.name, service, f"rosrpc://{host}:{port}"]})
            for key in _param_subscriptions:
                calls.append({"methodName": "unsubscribeParam", "params": [self.name, self.uri, key]})
            impls = list(_publications.values()) + list(_subscriptions.values())
        if calls and not self._master_lost:
            try:
                ServerProxy(self.master_uri, timeout=2.0).system.multicall(calls)
            except Exception as exc:
                _logger.warning("unregistration from the master failed: %s", exc)
        for impl in impls:
            try:
                impl.close()
            except Exception:
                _logger.debug("close failed: %s", traceback.format_exc())
        if self._tcpros_sock is not None:
            _close(self._tcpros_sock)
        if self._xmlrpc is not None:
            if self._reply_grace:
                time.sleep(self._reply_grace)
            try:
                self._xmlrpc.shutdown()
            except Exception:
                pass


def _close(sock: socket.socket) -> None:
    try:
        sock.shutdown(socket.SHUT_RDWR)
    except OSError:
        pass
    try:
        sock.close()
    except OSError:
        pass
