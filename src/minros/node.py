"""The node runtime: one :class:`Node` object owns everything a ROS node is.

A node is a name with remappings, a lifecycle (init, shutdown hooks, shutdown), what it offers
and asks for (publications, subscriptions, services, parameter subscriptions), the master it
registers those with, and two servers: the slave XML-RPC API (:class:`SlaveApi`) and one TCPROS
server that hands inbound connections to the publication or service they name.

Every master registration goes through the Node, so it can redo all of them when the master
restarts and undo all of them with one ``system.multicall`` on shutdown.

A process is one node, as in rospy: the module-level functions (``get_caller_id``,
``is_shutdown``, ``signal_shutdown``, ...) are rospy's API and delegate to the process's
default Node, which exists from import on (named ``<ns>/unnamed`` until ``init_node``). Tests
make Node objects of their own and drive registration, master restarts and shutdown in-process.

Lock order, where locks nest: ``_reg_lock`` (one registration exchange with the master at a
time) -> ``_registry_lock`` (the registries; a leaf, never held across a call out). The
lifecycle lock ``_state_lock`` is a leaf too.
"""

from __future__ import annotations

import atexit
import logging
import os
import socket
import sys
import threading
import time
import traceback
import urllib.parse
from typing import Any, Callable, Dict, List, Protocol, Sequence, Tuple

from minros import names, rosenv
from minros.exceptions import ROSException, ROSInitException, ServiceException
from minros.wire import admission, sockets, tcpros, trace
from minros.wire.masterapi import MasterClient, MasterIOError
from minros.wire.rosapi import ParameterInvalid, api, is_topic
from minros.wire.xmlrpc import ServerProxy, XmlRpcServer, after_reply

__all__ = [
    "DEFAULT_MASTER_URI",
    "Node",
    "Publication",
    "SlaveApi",
    "Subscription",
    "add_param_update_handler",
    "add_shutdown_hook",
    "default_node",
    "get_caller_id",
    "get_mappings",
    "get_master_uri",
    "get_name",
    "get_namespace",
    "get_node_uri",
    "get_tcpros_address",
    "is_initialized",
    "is_shutdown",
    "is_shutdown_requested",
    "master",
    "master_call",
    "master_call_once",
    "myargv",
    "on_shutdown",
    "register_service",
    "remap_name",
    "resolve_name",
    "resolve_name_without_node_name",
    "signal_shutdown",
    "spin",
    "subscribe_param",
    "unregister_service",
    "wait_for_shutdown",
]

DEFAULT_MASTER_URI = rosenv.DEFAULT_MASTER_URI
#: how often the master is probed to notice that it restarted
MASTER_PROBE_INTERVAL = 1.0
#: time allowed to read an inbound connection header, however slowly it trickles in
HEADER_TIMEOUT = 10.0
#: the admission policy of the TCPROS server (wire/admission.py): handshakes and service
#: connections; a service request may be large (roscpp allows 1 GB), hence the budget
TCPROS_LIMITS = admission.Limits(max_connections=1024, head_timeout=HEADER_TIMEOUT,
                                 budget=1 << 30)
#: timeout of XML-RPC calls to the master and to other nodes
XMLRPC_TIMEOUT = 10.0
#: a registration the master did not answer is retried this often
REGISTER_RETRY = 0.2
#: seconds close() waits for a registration in flight before it unregisters everything
CLOSE_REGISTRATION_WAIT = 2.0

_logger = logging.getLogger("minros.node")
#: what the user sees (console and /rosout once the client library's logging is up)
_rosout = logging.getLogger("rosout")


class Publication(Protocol):
    """What the node needs of a publication (``minros.client.topics`` implements it)."""

    resolved_name: str
    type: str
    md5sum: str

    def accept_subscriber(self, sock: socket.socket, addr: Any, header: Dict[str, str]) -> str | None: ...
    def get_stats(self) -> list: ...
    def get_stats_info(self) -> list: ...
    def close(self) -> None: ...


class Subscription(Protocol):
    """What the node needs of a subscription (``minros.client.topics`` implements it)."""

    resolved_name: str
    type: str

    def publisher_update(self, uris: List[str]) -> None: ...
    def get_stats(self) -> list: ...
    def get_stats_info(self) -> list: ...
    def close(self) -> None: ...


#: ``handler(sock, header, conn)``: serves one inbound service connection, owns the socket;
#: ``conn`` (an admission.Connection) is its part in the TCPROS server's admission policy
ServiceHandler = Callable[[socket.socket, Dict[str, str], admission.Connection], Any]
#: ``handler(key, value) -> bool``: a paramUpdate; True when the value was cached
ParamUpdateHandler = Callable[[str, Any], bool]


class Node:
    """One ROS node: names, lifecycle, registries, master registration and servers."""

    def __init__(self, argv: Sequence[str] | None = None) -> None:
        argv = list(sys.argv if argv is None else argv)
        # -- names: '<ns>/unnamed' until init() names the node
        self.argv_mappings: Dict[str, str] = names.load_mappings(argv)
        self.namespace_argv = argv
        self.caller_id = names.get_ros_namespace(argv=argv) + "unnamed"
        self._resolved_mappings: Dict[str, str] = {}
        self.init_argv: List[str] | None = None
        self.init_args: tuple | None = None
        # -- lifecycle
        self._state_lock = threading.Lock()
        self.initialized = False
        self._shutdown_requested = False
        self._shutdown_event = threading.Event()  # set once is_shutdown() is true
        self._shutdown_done = threading.Event()  # set when the shutdown sequence has finished
        self._shutdown_thread: threading.Thread | None = None
        self._client_hooks: List[Callable[[], Any]] = []
        self._internal_hooks: List[Callable[[str], Any]] = []
        # -- what the node offers and asks for
        self._registry_lock = threading.Lock()
        self.publications: Dict[str, Publication] = {}
        self.subscriptions: Dict[str, Subscription] = {}
        self.services: Dict[str, ServiceHandler] = {}
        self.param_subscriptions: set = set()
        self._param_update_handlers: List[ParamUpdateHandler] = []
        # -- master and servers (start())
        self._master_uri: str | None = None  # fixed by init(); until then read per call
        self.uri: str | None = None
        self.host = ""
        self._xmlrpc: XmlRpcServer | None = None
        self._xmlrpc_port = 0
        self._tcpros_port = 0
        self._tcpros_sock: socket.socket | None = None
        self._tcpros_lock = threading.Lock()
        self._allowed: Any = None  # ROS_ALLOWED_HOSTS, read by start()
        self._tcpros_admission = admission.Admission(TCPROS_LIMITS)
        self._inbound: Dict[int, socket.socket] = {}  # admission key -> inbound socket
        self._inbound_lock = threading.Lock()
        #: the typed Master API, as this node (its caller id and master URI as they are now)
        self.master = MasterClient(lambda: self.master_uri, lambda: self.caller_id,
                                   XMLRPC_TIMEOUT)
        self._reg_lock = threading.Lock()
        self._master_pid: int | None = None
        self._master_lost = False
        self._warned_master = False
        self._started = False
        self._named = False
        self._closed = threading.Event()

    # ------------------------------------------------------------------------------ names

    @property
    def name(self) -> str:
        return self.caller_id

    @property
    def master_uri(self) -> str:
        """``__master:=``, else ROS_MASTER_URI, else the default (fixed once init_node ran)."""
        if self._master_uri is not None:
            return self._master_uri
        return rosenv.get_master_uri(remapped=self.argv_mappings.get("__master"))

    def get_namespace(self) -> str:
        """The node's namespace with trailing '/'."""
        return names.namespace(self.caller_id)

    def get_mappings(self) -> Dict[str, str]:
        """Command-line remappings (as given, unresolved; ``__name`` etc. included)."""
        return dict(self.argv_mappings)

    def resolve_name(self, name: str, caller_id: str | None = None) -> str:
        """Resolve ``name`` relative to the node (or ``caller_id``), applying remappings."""
        if caller_id is None:
            caller_id = self.caller_id
        if not name:
            return names.namespace(caller_id)
        resolved = names.resolve_name(name, caller_id)
        if caller_id == self.caller_id:
            mappings = self._resolved_mappings
        else:
            mappings = names.resolve_mappings(self._plain_mappings(), caller_id)
        return mappings.get(resolved, resolved)

    def resolve_name_without_node_name(self, name: str) -> str:
        """Resolve a topic/service name created before init_node (rospy semantics): relative to
        the namespace, with the command-line remappings; ``~name`` is an error then."""
        if names.is_private(name):
            raise ValueError("~name topics cannot be created before init_node() has been called")
        fake_caller_id = names.ns_join(names.get_ros_namespace(argv=self.namespace_argv), "node")
        resolved = names.resolve_name(name, fake_caller_id)
        for src, dst in self._plain_mappings().items():
            if names.resolve_name(src, fake_caller_id) == resolved:
                if names.is_private(dst):
                    raise ROSInitException(
                        f"due to the way this node is written, {name} cannot be remapped to a ~name. \n"
                        "The declaration of topics/services must be moved after the call to init_node()")
                return names.resolve_name(dst, fake_caller_id)
        return resolved

    def resolve_topic_name(self, name: str) -> str:
        """A topic or service name as the client library resolves it: against the node once
        init_node named it, against the namespace before."""
        if self._named:
            return self.resolve_name(name)
        return self.resolve_name_without_node_name(name)

    def remap_name(self, name: str, caller_id: str | None = None) -> str:
        """Remap ``name`` without otherwise resolving it (rospy.remap_name)."""
        if caller_id is None:
            caller_id = self.caller_id
        if name in self.argv_mappings:
            return names.resolve_name(self.argv_mappings[name], caller_id)
        return name

    def _plain_mappings(self) -> Dict[str, str]:
        """Remappings of graph names (not the ``__name``/``__ns``/... special keys)."""
        return {k: v for k, v in self.argv_mappings.items() if not k.startswith("__")}

    # -------------------------------------------------------------------------- lifecycle

    def is_shutdown(self) -> bool:
        return self._shutdown_event.is_set()

    def is_shutdown_requested(self) -> bool:
        return self._shutdown_requested or self._shutdown_event.is_set()

    def wait_for_shutdown(self, timeout: float | None) -> bool:
        """Block up to ``timeout`` seconds; True if the node is (or becomes) shut down."""
        return self._shutdown_event.wait(timeout)

    def on_shutdown(self, hook: Callable[[], Any]) -> None:
        """Call ``hook()`` when the node shuts down, before it unregisters from the master."""
        if not callable(hook):
            raise TypeError(f"shutdown hook [{hook}] must be a function or callable object: {type(hook)}")
        with self._state_lock:
            run_now = self._shutdown_event.is_set()
            if not run_now:
                self._client_hooks.append(hook)
        if run_now:
            hook()

    def add_shutdown_hook(self, hook: Callable[[str], Any]) -> None:
        """Internal: ``hook(reason)`` runs during shutdown after the client hooks."""
        with self._state_lock:
            self._internal_hooks.append(hook)

    def signal_shutdown(self, reason: str) -> None:
        """Shut the node down: client hooks, internal hooks, one unregistration multicall,
        then the transports and servers close. A second call waits for the first to finish
        (e.g. atexit while ``rosnode kill`` is unregistering) unless it is that very call."""
        with self._state_lock:
            first = not self._shutdown_requested
            if first:
                self._shutdown_requested = True
                self._shutdown_thread = threading.current_thread()
                client_hooks, self._client_hooks = self._client_hooks, []
            else:
                in_progress_here = self._shutdown_thread is threading.current_thread()
        if not first:
            if not in_progress_here:
                self._shutdown_done.wait(5.0)
            return
        try:
            _logger.info("signal_shutdown [%s]", reason)
            for hook in client_hooks:
                try:
                    hook()
                except Exception:
                    traceback.print_exc()
            self._shutdown_event.set()
            with self._state_lock:
                internal, self._internal_hooks = self._internal_hooks, []
            for internal_hook in internal:
                try:
                    internal_hook(reason)
                except Exception as exc:
                    sys.stderr.write(f"signal_shutdown hook error[{exc}]\n")
            self.close()
        finally:
            self._shutdown_done.set()

    def spin(self) -> None:
        """Block until the node is shut down."""
        if not self.initialized:
            raise ROSInitException("client code must call rospy.init_node() first")
        try:
            while not self._shutdown_event.wait(0.5):
                pass
        except KeyboardInterrupt:
            self.signal_shutdown("keyboard interrupt")

    # ------------------------------------------------------------------------------- init

    def init(self, name: str, argv: Sequence[str] | None = None, anonymous: bool = False,
             xmlrpc_port: int = 0, tcpros_port: int = 0, args_key: tuple = ()) -> bool:
        """Name the node, start its servers and register it (the network half of
        ``rospy.init_node``). False when it was already initialised with the same
        ``args_key``; ROSException when with different ones."""
        if not name:
            raise ValueError("name must not be empty")
        if names.SEP in name:
            raise ValueError("namespaces are not allowed in node names")
        with self._state_lock:
            if self.init_args is not None:
                if self.init_args != args_key:
                    raise ROSException("rospy.init_node() has already been called with "
                                       "different arguments: " + str(self.init_args))
                return False
            self.init_args = args_key
        if argv is None:  # as rospy: the names from today's sys.argv, the mappings from import
            argv = list(sys.argv)
        else:
            argv = list(argv)
            self.argv_mappings = names.load_mappings(argv)
        self.namespace_argv = argv
        self.init_argv = argv
        self._master_uri = rosenv.get_master_uri(remapped=self.argv_mappings.get("__master"))
        if "__name" in self.argv_mappings:
            name = self.argv_mappings["__name"]
            anonymous = False
        if anonymous:
            name = f"{name}_{os.getpid()}_{int(time.time() * 1000)}"
        if not names.is_legal_base_name(name):
            import warnings

            warnings.warn(f"'{name}' is not a legal ROS base name. This may cause problems with "
                          "other ROS tools.", stacklevel=3)
        self.caller_id = names.resolve_name(name, names.get_ros_namespace(argv=argv) + "unnamed")
        self._resolved_mappings = names.resolve_mappings(self._plain_mappings(), self.caller_id)
        self._named = True
        self._xmlrpc_port, self._tcpros_port = xmlrpc_port, tcpros_port
        self.start()
        if self.is_shutdown_requested():
            raise ROSInitException("init_node interrupted before it could complete")
        # private parameters from the command line (_name:=value, YAML-typed)
        try:
            params = names.load_command_line_node_params(argv)
        except ValueError as exc:
            raise ROSInitException(str(exc)) from None
        for key, value in params.items():
            self.master_call("setParam", names.ns_join(self.caller_id, key), value)
        self.initialized = True  # as rospy: before /rosout and /clock are set up
        return True

    # ------------------------------------------------------------------------ the network

    def host_name(self) -> str:
        """The host this node advertises in its URIs (``__hostname``/``__ip``, ROS_HOSTNAME,
        ROS_IP, else the machine's name)."""
        override = rosenv.get_address_override(argv=self.init_argv or self.namespace_argv)
        return override if override else rosenv.get_host_name()

    def bind_address(self) -> str:
        """Loopback when the advertised address is loopback, else every interface."""
        return rosenv.get_bind_address(
            rosenv.get_address_override(argv=self.init_argv or self.namespace_argv))

    def start(self) -> None:
        """Start the slave API, register everything with the master, watch the master."""
        self.host = self.host_name()
        try:
            self._allowed = rosenv.allowed_hosts()
        except ValueError as exc:
            raise ROSInitException(str(exc)) from None
        self._tcpros_admission = admission.Admission(
            TCPROS_LIMITS, self._allowed, what=f"node [{self.caller_id}]")
        self._xmlrpc = XmlRpcServer(SlaveApi(self), host=self.bind_address(), port=self._xmlrpc_port,
                                    allowed=self._allowed, on_refused=self._refused,
                                    what=f"node [{self.caller_id}]")
        self._xmlrpc.start()
        self.uri = f"http://{self.host}:{self._xmlrpc.port}/"
        _logger.info("ROS Slave URI: [%s]", self.uri)
        trace.set_node(self.caller_id, self.uri, self.master_uri)
        if self._tcpros_port:
            self.tcpros_address()
        self._started = True
        self._register_all(first=True)
        threading.Thread(target=self._monitor_master, name="minros-master-probe", daemon=True).start()

    def master_call(self, method: str, *args: Any) -> list:
        """``master.method(caller_id, *args)``: the raw triplet; works before init_node. The
        connection is kept alive per thread; MasterIOError (an OSError) when the master is down."""
        return self.master.raw(method, *args)

    def master_call_once(self, method: str, *args: Any) -> list:
        """``master.method(caller_id, *args)`` on a fresh connection, closed afterwards."""
        proxy = ServerProxy(self.master_uri, timeout=XMLRPC_TIMEOUT)
        try:
            return getattr(proxy, method)(self.caller_id, *args)
        finally:
            proxy.close()

    def tcpros_address(self) -> Tuple[str, int]:
        """(advertised host, port) of the node's TCPROS server (started on first use)."""
        if not self._started:
            raise ROSInitException("client code must call rospy.init_node() first")
        with self._tcpros_lock:
            if self._tcpros_sock is None:
                server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
                server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                server.bind((self.bind_address(), self._tcpros_port))
                server.listen(128)
                self._tcpros_sock = server
                threading.Thread(target=self._accept_loop, args=(server,),
                                 name="minros-tcpros-server", daemon=True).start()
            return self.host, self._tcpros_sock.getsockname()[1]

    @staticmethod
    def _refused(peer: str, reason: str) -> None:
        """A peer outside ROS_ALLOWED_HOSTS (one line per peer a minute, by the policy)."""
        _rosout.warning("%s", reason)

    def _accept_loop(self, server: socket.socket) -> None:
        adm = self._tcpros_admission
        while not self._closed.is_set():
            try:
                sock, addr = server.accept()
            except OSError:
                if self._closed.is_set():
                    return
                self._closed.wait(0.01)  # e.g. out of file descriptors: back off
                continue
            key = adm.new_key()
            try:
                victims = adm.admit(key, addr[0], sock.getsockname()[0])
            except admission.Refused as refused:
                if refused.report:
                    self._refused(addr[0], str(refused))
                sock.settimeout(1.0)
                try:  # the peer reads it where it expects the answer to its header
                    sock.sendall(tcpros.encode_error_header(str(refused)))
                except OSError:
                    pass
                sockets.close(sock)
                continue
            except OSError:  # the peer left already
                sockets.close(sock)
                continue
            self._evict_inbound(victims)
            with self._inbound_lock:
                self._inbound[key] = sock
            try:
                threading.Thread(target=self._handle_inbound, args=(sock, addr, key),
                                 name="minros-tcpros-inbound", daemon=True).start()
            except RuntimeError:  # cannot start a thread: drop this peer
                self._forget_inbound(key)
                sockets.close(sock)

    def _evict_inbound(self, keys: List[Any]) -> None:
        """Close inbound connections the admission policy chose to make room."""
        for key in keys:
            with self._inbound_lock:
                sock = self._inbound.get(key)
            if sock is not None:
                try:
                    sock.shutdown(socket.SHUT_RDWR)  # its thread sees the end and cleans up
                except OSError:
                    pass

    def _forget_inbound(self, key: Any) -> None:
        with self._inbound_lock:
            self._inbound.pop(key, None)
        self._tcpros_admission.leave(key)

    def _handle_inbound(self, sock: socket.socket, addr: Any, key: Any) -> None:
        """Read the connection header and hand the socket to the topic or service."""
        sock = trace.watch(sock, "accept")
        conn = admission.Connection(self._tcpros_admission, key, self._evict_inbound)
        try:
            conn.reading()
            try:
                header = sockets.read_header(
                    sock, deadline=time.monotonic() + conn.limits.head_timeout,
                    charge=conn.charge)
                sock.settimeout(None)
            except (OSError, tcpros.HeaderError, admission.Refused) as exc:
                if not self.is_shutdown_requested() and not conn.evicted():
                    _rosout.warning("Inbound TCP/IP connection failed: %s", exc)
                sockets.close(sock)
                return
            conn.release()
            conn.busy()
            try:
                error = self._dispatch_inbound(sock, addr, header, conn)
            except Exception as exc:
                error = f"internal error: {exc}"
                _logger.error("inbound connection failed: %s", traceback.format_exc())
            if error is not None:
                if self.is_shutdown_requested():
                    error = "node shutting down"
                else:  # rospy's wording, header dict included
                    _rosout.warning("Could not process inbound connection: %s%s", error, header)
                try:
                    sock.sendall(tcpros.encode_error_header(error))
                except OSError:
                    pass
                sockets.close(sock)
        finally:
            # a topic connection lives on with its publication; a service one has ended
            self._forget_inbound(key)

    def _dispatch_inbound(self, sock: socket.socket, addr: Any, header: Dict[str, str],
                          conn: admission.Connection) -> str | None:
        """Hand a connection to what its header names; the error text when it cannot be."""
        if "topic" in header:
            if self.is_shutdown_requested():
                return "Node is shutting down"
            pub = self.publications.get(header["topic"])
            if pub is None:
                return tcpros.publisher_header_error(header, self.caller_id, {
                    t: (p.type, p.md5sum) for t, p in list(self.publications.items())}) or (
                    f"[{self.caller_id}] is not a publisher of [{header['topic']}]")
            return pub.accept_subscriber(sock, addr, header)
        if "service" in header:
            handler = self.services.get(header["service"])
            if handler is None:
                return f"[{self.caller_id}] is not a provider of [{header['service']}]"
            handler(sock, header, conn)
            return None
        return "no topic or service name detected"

    # ------------------------------------------------------------------------- registries

    def add_publication(self, pub: Publication, announce: bool = True) -> None:
        with self._registry_lock:
            self.publications[pub.resolved_name] = pub
        if announce:
            self.announce("pub", pub)

    def remove_publication(self, pub: Publication) -> None:
        with self._registry_lock:
            if self.publications.get(pub.resolved_name) is not pub:
                return
            del self.publications[pub.resolved_name]
        self._withdraw("pub", pub.resolved_name, "unregisterPublisher", pub.resolved_name, self.uri)

    def add_subscription(self, sub: Subscription, announce: bool = True) -> None:
        with self._registry_lock:
            self.subscriptions[sub.resolved_name] = sub
        if announce:
            self.announce("sub", sub)

    def remove_subscription(self, sub: Subscription) -> None:
        with self._registry_lock:
            if self.subscriptions.get(sub.resolved_name) is not sub:
                return
            del self.subscriptions[sub.resolved_name]
        self._withdraw("sub", sub.resolved_name, "unregisterSubscriber", sub.resolved_name, self.uri)

    def announce(self, kind: str, endpoint: Publication | Subscription) -> None:
        """Register a publication ("pub") or subscription ("sub") with the master now (before
        start() there is nothing to do: start() registers everything in the registries)."""
        if not self._started:
            return
        name, type_ = endpoint.resolved_name, endpoint.type
        register = self._register_publisher if kind == "pub" else self._register_subscriber
        self._announce(kind, name, lambda: register(name, type_))

    def register_service(self, resolved_name: str, handler: ServiceHandler) -> None:
        """Serve ``resolved_name`` on the TCPROS server and register it with the master.

        ``handler(sock, header, conn)`` runs in the connection's thread for inbound connections
        whose header names this service; it owns the socket from then on, and tells ``conn``
        (the connection's admission) when it waits for, reads or serves a request.
        ServiceException if this node already serves ``resolved_name`` (checked under the
        registry lock: no two winners).
        """
        with self._registry_lock:
            if resolved_name in self.services:
                raise ServiceException(f"service [{resolved_name}] already registered")
            self.services[resolved_name] = handler
        if self._started:
            self._announce("srv", resolved_name, lambda: self._register_service(resolved_name))

    def unregister_service(self, resolved_name: str) -> None:
        with self._registry_lock:
            if self.services.pop(resolved_name, None) is None:
                return
        if self._started:
            self._withdraw("srv", resolved_name, "unregisterService", resolved_name, self._rosrpc_uri())

    def subscribe_param(self, resolved_key: str) -> Any:
        """subscribeParam with the master; later paramUpdate calls go to the handlers. Returns
        the current value (``{}`` when unset, as the master answers)."""
        if not self._started:
            raise ROSInitException("client code must call rospy.init_node() first")
        with self._registry_lock:
            self.param_subscriptions.add(resolved_key)
        code, msg, value = self.master_call("subscribeParam", self.uri, resolved_key)
        if code != 1:
            raise ROSException(f"cannot subscribe to parameter [{resolved_key}]: {msg}")
        return value

    def add_param_update_handler(self, handler: ParamUpdateHandler) -> None:
        """``handler(key, value) -> bool`` is called for every slave paramUpdate."""
        with self._registry_lock:
            self._param_update_handlers.append(handler)

    def param_update(self, key: str, value: Any) -> bool:
        """A paramUpdate from the master: True if the node cares about ``key``."""
        cached = False
        for handler in list(self._param_update_handlers):
            try:
                cached = bool(handler(key, value)) or cached
            except Exception:
                _logger.error("paramUpdate handler failed: %s", traceback.format_exc())
        if cached:
            return True
        prefix = key.rstrip("/") + "/"
        with self._registry_lock:
            return any(k == key or k.startswith(prefix) or key.startswith(k.rstrip("/") + "/")
                       for k in self.param_subscriptions)

    # ----------------------------------------------------------------------- registration

    def _rosrpc_uri(self) -> str:
        host, port = self.tcpros_address()
        return f"rosrpc://{host}:{port}"

    def _register_publisher(self, topic: str, type_: str) -> None:
        code, msg, _ = self.master_call("registerPublisher", topic, type_, self.uri)
        self._check_registered(code, "pub", topic, msg)

    def _register_subscriber(self, topic: str, type_: str) -> None:
        code, msg, pubs = self.master_call("registerSubscriber", topic, type_, self.uri)
        self._check_registered(code, "sub", topic, msg)
        if code == 1:
            sub = self.subscriptions.get(topic)
            if sub is not None:
                sub.publisher_update(pubs)

    def _register_service(self, service: str) -> None:
        code, msg, _ = self.master_call("registerService", service, self._rosrpc_uri(), self.uri)
        self._check_registered(code, "srv", service, msg)

    def _resubscribe_param(self, key: str) -> None:
        code, msg, value = self.master_call("subscribeParam", self.uri, key)
        self._check_registered(code, "param", key, msg)
        if code == 1:
            for handler in list(self._param_update_handlers):
                try:
                    handler(key, value)
                except Exception:
                    _logger.debug("paramUpdate handler failed: %s", traceback.format_exc())

    @staticmethod
    def _check_registered(code: int, kind: str, name: str, msg: str) -> None:
        if code != 1:
            _logger.error("master refused to register %s [%s]: %s", kind, name, msg)

    def _announce(self, kind: str, name: str, call: Callable[[], None]) -> None:
        """Run one registration call; on a master failure the probe thread redoes all later."""
        try:
            with self._reg_lock:
                if self._closed.is_set():
                    return  # close() has unregistered what it found: this would outlive the node
                call()
        except Exception as exc:
            self._master_lost = True
            _logger.warning("cannot register %s [%s] with the master now (%s); will retry",
                            kind, name, exc)

    def _withdraw(self, kind: str, name: str, method: str, *args: Any) -> None:
        """One unregistration call (none once shutdown started: the multicall does them all)."""
        if not self._started or self.is_shutdown_requested():
            return
        try:
            self.master_call(method, *args)
        except Exception as exc:
            _logger.warning("cannot unregister %s [%s]: %s", kind, name, exc)

    def _register_all(self, first: bool = False) -> None:
        """Register every publication, subscription, service and parameter subscription,
        retrying every REGISTER_RETRY seconds until the master answers."""
        while not self.is_shutdown_requested():
            try:
                with self._reg_lock:
                    code, _msg, pid = self.master_call("getPid")
                    with self._registry_lock:
                        pubs = [(t, p.type) for t, p in self.publications.items()]
                        subs = [(t, s.type) for t, s in self.subscriptions.items()]
                        srvs = list(self.services)
                        params = list(self.param_subscriptions)
                    for topic, type_ in pubs:
                        self._register_publisher(topic, type_)
                    for topic, type_ in subs:
                        self._register_subscriber(topic, type_)
                    for service in srvs:
                        self._register_service(service)
                    for key in params:
                        self._resubscribe_param(key)
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
                    if isinstance(exc, MasterIOError) and exc.errcode == 403:
                        # not "may not be running": it runs and refuses us (ROS_ALLOWED_HOSTS)
                        text = (f"The master [{self.master_uri}] refuses this node: {exc.errmsg}. "
                                "Will keep trying.")
                    if first:
                        _rosout.error(text)
                    else:
                        _logger.error(text)
                _logger.debug("registration failed: %s", exc)
                if self._shutdown_event.wait(REGISTER_RETRY):
                    return

    def _monitor_master(self) -> None:
        """Probe the master every second; re-register after it restarted or came back."""
        proxy = ServerProxy(self.master_uri, timeout=2.0)
        while not self._shutdown_event.wait(MASTER_PROBE_INTERVAL):
            if self._closed.is_set():
                return
            try:
                code, _msg, pid = proxy.getPid(self.caller_id)
            except Exception:
                proxy = ServerProxy(self.master_uri, timeout=2.0)
                if not self._master_lost:
                    _logger.warning("lost contact with the master at %s", self.master_uri)
                self._master_lost = True
                continue
            if self._master_lost or (code == 1 and pid != self._master_pid):
                self._warned_master = True
                self._register_all()

    # --------------------------------------------------------------------------- shutdown

    def _unregistration_calls(self) -> List[Dict[str, Any]]:
        """Every unregistration, as one system.multicall's call list."""
        me = self.caller_id
        with self._registry_lock:
            calls = [{"methodName": "unregisterSubscriber", "params": [me, t, self.uri]}
                     for t in self.subscriptions]
            calls += [{"methodName": "unregisterPublisher", "params": [me, t, self.uri]}
                      for t in self.publications]
            if self.services and self._tcpros_sock is not None:
                rosrpc = f"rosrpc://{self.host}:{self._tcpros_sock.getsockname()[1]}"
                calls += [{"methodName": "unregisterService", "params": [me, s, rosrpc]}
                          for s in self.services]
            calls += [{"methodName": "unsubscribeParam", "params": [me, self.uri, k]}
                      for k in self.param_subscriptions]
        return calls

    def close(self) -> None:
        """Unregister everything with one multicall, close every connection, stop the servers."""
        if self._closed.is_set():
            return
        self._closed.set()
        if not self._started:
            return
        # after any registration in flight (a Ctrl-C in the middle of rospy.Subscriber(...)):
        # the master must see it before the unregistration, or it outlives the node there.
        # Bounded: a registration stuck on a frozen master must not hold up the shutdown.
        locked = self._reg_lock.acquire(timeout=CLOSE_REGISTRATION_WAIT)
        try:
            calls = self._unregistration_calls()
            if calls:
                # tried even when the probe lost the master: a master that was only slow for a
                # moment would otherwise keep our registrations forever; one that is gone costs
                # a short wait
                try:
                    ServerProxy(self.master_uri, timeout=0.5 if self._master_lost else 2.0
                                ).system.multicall(calls)
                except Exception as exc:
                    _logger.warning("unregistration from the master failed: %s", exc)
        finally:
            if locked:
                self._reg_lock.release()
        with self._registry_lock:
            endpoints = [*self.publications.values(), *self.subscriptions.values()]
        for endpoint in endpoints:
            try:
                endpoint.close()
            except Exception:
                _logger.debug("close failed: %s", traceback.format_exc())
        sockets.close(self._tcpros_sock)
        if self._xmlrpc is not None:
            self._xmlrpc.shutdown()


# ------------------------------------------------------------------------------- slave API


_INT32_MAX = (1 << 31) - 1


def _xmlrpc_ints(value: Any) -> Any:
    """Byte counters of a long-lived connection outgrow XML-RPC's 32-bit int: saturate them."""
    if isinstance(value, list):
        return [_xmlrpc_ints(v) for v in value]
    if isinstance(value, int) and not isinstance(value, bool) and value > _INT32_MAX:
        return _INT32_MAX
    return value


class SlaveApi:
    """The node's XML-RPC API (called by the master, tools and other nodes), with rospy's
    argument checks and triplets."""

    def __init__(self, node: Node) -> None:
        self._node = node

    def _endpoints(self) -> Tuple[list, list]:
        node = self._node
        with node._registry_lock:
            return list(node.publications.values()), list(node.subscriptions.values())

    @api("")
    def getUri(self, caller_id):
        return 1, "", self._node.uri

    @api("")
    def getName(self, caller_id):
        return 1, "", self._node.name

    @api([])
    def getBusStats(self, caller_id):
        pubs, subs = self._endpoints()
        return 1, "", _xmlrpc_ints([[p.get_stats() for p in pubs], [s.get_stats() for s in subs], []])

    @api([])
    def getBusInfo(self, caller_id):
        pubs, subs = self._endpoints()
        info: list = []
        for endpoint in pubs + subs:
            info.extend(endpoint.get_stats_info())
        return 1, "bus info", info

    @api("")
    def getMasterUri(self, caller_id):
        uri = self._node.master_uri
        if uri:
            return 1, uri, uri
        return 0, "master URI not set", ""

    @api(0, (None,))
    def shutdown(self, caller_id, msg=""):
        if msg:
            print(f"shutdown request: {msg}", flush=True)
        else:
            print("shutdown requst", flush=True)  # sic: rospy's text, kept byte for byte
        reason = f"external shutdown request from [{caller_id}]: [{msg}]"
        # the reply leaves first, then the servers close
        after_reply(lambda: self._node.signal_shutdown(reason))
        return 1, "shutdown", 0

    @api(-1)
    def getPid(self, caller_id):
        return 1, "", os.getpid()

    @api([])
    def getSubscriptions(self, caller_id):
        _, subs = self._endpoints()
        return 1, "subscriptions", [[s.resolved_name, s.type] for s in subs]

    @api([])
    def getPublications(self, caller_id):
        pubs, _ = self._endpoints()
        return 1, "publications", [[p.resolved_name, p.type] for p in pubs]

    @api(-1, (None, None))
    def paramUpdate(self, caller_id, key, value):
        if not key or not isinstance(key, str):
            raise ParameterInvalid("ERROR: parameter [parameter_key] must be a non-empty string")
        if not names.is_global(key):
            raise ParameterInvalid("ERROR: parameter [parameter_key] must be a globally referenced name")
        if not self._node.param_update(key, value):
            return -1, "not subscribed", 0
        return 1, "", 0

    @api(-1, (is_topic("topic"), None))
    def publisherUpdate(self, caller_id, topic, publishers):
        if not isinstance(publishers, list):
            raise ParameterInvalid("ERROR: param [publishers] must be a list")
        for uri in publishers:
            if not isinstance(uri, str):
                raise ParameterInvalid("ERROR: param [publishers] must be a list of strings")
            parsed = urllib.parse.urlparse(uri)
            if not parsed.scheme or not parsed.netloc:
                raise ParameterInvalid(f"ERROR: param [publishers] does not contain valid URLs [{uri}]")
        sub = self._node.subscriptions.get(topic)
        if sub is not None:
            sub.publisher_update(publishers)
        return 1, "", 0

    @api([], (is_topic("topic"), None))
    def requestTopic(self, caller_id, topic, protocols):
        if not protocols:
            raise ParameterInvalid("ERROR: parameter [protocols] must be specified and non-empty")
        if not isinstance(protocols, list):
            raise ParameterInvalid("ERROR: parameter [protocols] must be a list of protocols")
        if topic not in self._node.publications:
            return -1, f"Not a publisher of [{topic}]", []
        for protocol in protocols:
            if isinstance(protocol, list) and protocol and protocol[0] == tcpros.TCPROS:
                host, port = self._node.tcpros_address()
                return 1, f"ready on {host}:{port}", [tcpros.TCPROS, host, port]
        return 0, "no supported protocol implementations", []


# ------------------------------------------------------------------ the process's node (rospy)

_default = Node()
atexit.register(lambda: _default.signal_shutdown("atexit"))


def default_node() -> Node:
    """The node this process is (rospy's module-level API acts on it)."""
    return _default


def get_caller_id() -> str:
    """The node's global name ('/unnamed' in its namespace before init_node)."""
    return _default.caller_id


get_name = get_caller_id


def get_namespace() -> str:
    """The node's namespace with trailing '/'."""
    return _default.get_namespace()


def get_mappings() -> Dict[str, str]:
    """Command-line remappings (as given, unresolved; ``__name`` etc. included)."""
    return _default.get_mappings()


def resolve_name(name: str, caller_id: str | None = None) -> str:
    """Resolve ``name`` relative to the node (or ``caller_id``), applying remappings."""
    return _default.resolve_name(name, caller_id)


def resolve_name_without_node_name(name: str) -> str:
    """Resolve a name created before init_node (see Node.resolve_name_without_node_name)."""
    return _default.resolve_name_without_node_name(name)


def remap_name(name: str, caller_id: str | None = None, resolved: bool = True) -> str:
    """Remap ``name`` without otherwise resolving it (rospy.remap_name)."""
    return _default.remap_name(name, caller_id)


def myargv(argv: List[str] | None = None) -> List[str]:
    """``argv`` (default sys.argv) without remapping arguments."""
    return names.strip_remapping_args(sys.argv if argv is None else argv)


def is_initialized() -> bool:
    """True once init_node has registered the node (publishing is allowed from then on)."""
    return _default.initialized


def is_shutdown() -> bool:
    return _default.is_shutdown()


def is_shutdown_requested() -> bool:
    return _default.is_shutdown_requested()


def wait_for_shutdown(timeout: float | None) -> bool:
    """Block up to ``timeout`` seconds; True if the node is (or becomes) shut down."""
    return _default.wait_for_shutdown(timeout)


def on_shutdown(hook: Callable[[], Any]) -> None:
    """Call ``hook()`` when the node shuts down, before it unregisters from the master."""
    _default.on_shutdown(hook)


def add_shutdown_hook(hook: Callable[[str], Any]) -> None:
    """Internal: ``hook(reason)`` runs during shutdown after the client hooks."""
    _default.add_shutdown_hook(hook)


def signal_shutdown(reason: str) -> None:
    """Shut the node down: client hooks, one unregistration multicall, close transports."""
    _default.signal_shutdown(reason)


def spin() -> None:
    """Block until the node is shut down."""
    _default.spin()


def get_master_uri() -> str:
    return _default.master_uri


def get_node_uri() -> str | None:
    return _default.uri


def get_tcpros_address() -> Tuple[str, int]:
    """(advertised host, port) of this process's TCPROS server (started on first use)."""
    return _default.tcpros_address()


def master() -> MasterClient:
    """The master of this process's node, as that node (works before init_node)."""
    return _default.master


def master_call(method: str, *args: Any) -> list:
    """``master.method(caller_id, *args)`` returning the raw triplet (works before init_node)."""
    return _default.master_call(method, *args)


def master_call_once(method: str, *args: Any) -> list:
    """``master.method(caller_id, *args)`` on a fresh connection (works before init_node)."""
    return _default.master_call_once(method, *args)


def register_service(resolved_name: str, handler: ServiceHandler) -> None:
    _default.register_service(resolved_name, handler)


def unregister_service(resolved_name: str) -> None:
    _default.unregister_service(resolved_name)


def subscribe_param(resolved_key: str) -> Any:
    return _default.subscribe_param(resolved_key)


def add_param_update_handler(handler: ParamUpdateHandler) -> None:
    _default.add_param_update_handler(handler)
