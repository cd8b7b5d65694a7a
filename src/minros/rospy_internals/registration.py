"""rospy.impl.registration: the topic and service managers, registration listeners and the
registration manager, with rospy's names.

The default topic manager (:func:`get_topic_manager`) and service manager
(:func:`get_service_manager`) are views of this process's minros node: its publications,
subscriptions and services are theirs, and what they acquire or register is the node's
(announced to the master when the node runs). ``rospy.impl.registration`` *is* this module:
callers replace its ``is_shutdown`` or the managers, and the change must be seen here.
"""

from __future__ import annotations

import logging
import threading
import traceback
import xmlrpc.client
from typing import Any, Dict, List, Optional, Tuple

from minros import node as _node
from minros.client import topics as _topics
from minros.exceptions import ServiceException
from minros.wire.xmlrpc import ServerProxy

#: replaced by callers (rospy's tests stub it); looked up at each use
is_shutdown = _node.is_shutdown

_logger = logging.getLogger("rospy.registration")


class Registration:
    """Kinds of registration: ``'pub'``, ``'sub'``, ``'srv'``."""

    PUB = "pub"
    SUB = "sub"
    SRV = "srv"


class RegistrationListener:
    """Told of each registration and unregistration."""

    def reg_added(self, resolved_name: str, data_type_or_uri: str, reg_type: str) -> None:
        """``resolved_name`` (of ``data_type`` or at service ``uri``) was registered."""

    def reg_removed(self, resolved_name: str, data_type_or_uri: str, reg_type: str) -> None:
        """``resolved_name`` was unregistered."""


class RegistrationListeners:
    """The listeners, each told in turn; one that raises does not stop the others."""

    def __init__(self) -> None:
        self.listeners: List[RegistrationListener] = []
        self.lock = threading.Lock()

    def add_listener(self, listener: RegistrationListener) -> None:
        with self.lock:
            self.listeners.append(listener)

    def notify_removed(self, resolved_name: str, data_type_or_uri: str, reg_type: str) -> None:
        self._notify("reg_removed", resolved_name, data_type_or_uri, reg_type)

    def notify_added(self, resolved_name: str, data_type: str, reg_type: str) -> None:
        self._notify("reg_added", resolved_name, data_type, reg_type)

    def _notify(self, method: str, *args: str) -> None:
        with self.lock:
            listeners = list(self.listeners)
        for listener in listeners:
            try:
                getattr(listener, method)(*args)
            except Exception:
                _logger.error(traceback.format_exc())

    def clear(self) -> None:
        with self.lock:
            del self.listeners[:]


_registration_listeners = RegistrationListeners()


def get_registration_listeners() -> RegistrationListeners:
    return _registration_listeners


# ---------------------------------------------------------------------------------------------
# the topic manager

class TopicManager:
    """The node's publications and subscriptions under rospy's names (rospy.topics'
    ``_TopicManager``): acquiring one makes or shares the node's, as Publisher() does."""

    def __init__(self) -> None:
        self.lock = threading.RLock()
        self.closed = False

    @staticmethod
    def _registry(reg_type: str) -> Dict[str, Any]:
        me = _node.default_node()
        return me.publications if reg_type == Registration.PUB else me.subscriptions

    @property
    def pubs(self) -> Dict[str, Any]:
        return dict(self._registry(Registration.PUB))

    @property
    def subs(self) -> Dict[str, Any]:
        return dict(self._registry(Registration.SUB))

    def acquire_impl(self, reg_type: str, resolved_name: str, data_class: Any) -> Any:
        """The topic's publication or subscription, made if needed (reference counted)."""
        if reg_type not in (Registration.PUB, Registration.SUB):
            raise TypeError(f"invalid reg_type: {reg_type}")
        return _topics._acquire(reg_type, resolved_name, data_class)

    def release_impl(self, reg_type: str, resolved_name: str) -> None:
        impl = self.get_impl(reg_type, resolved_name)
        if impl is not None:
            _topics._release(reg_type, impl)

    def get_impl(self, reg_type: str, resolved_name: str) -> Any:
        impl = self._registry(reg_type).get(resolved_name)
        return None if impl is None or impl.closed else impl

    def get_publisher_impl(self, resolved_name: str) -> Any:
        return self.get_impl(Registration.PUB, resolved_name)

    def get_subscriber_impl(self, resolved_name: str) -> Any:
        return self.get_impl(Registration.SUB, resolved_name)

    def has_subscription(self, resolved_name: str) -> bool:
        return self.get_subscriber_impl(resolved_name) is not None

    def has_publication(self, resolved_name: str) -> bool:
        return self.get_publisher_impl(resolved_name) is not None

    def get_publications(self) -> List[List[str]]:
        """``[[topic, type], ...]`` of this node's publications."""
        return [[name, impl.type] for name, impl in self.pubs.items() if not impl.closed]

    def get_subscriptions(self) -> List[List[str]]:
        return [[name, impl.type] for name, impl in self.subs.items() if not impl.closed]

    def get_topics(self) -> List[str]:
        return sorted({name for name, _ in self.get_publications() + self.get_subscriptions()})

    def check_all(self) -> None:
        """rospy polls its connections for errors here; minros's notice by themselves."""

    def close_all(self) -> None:
        """Close every publication and subscription (the node's shutdown does it too)."""
        self.closed = True
        me = _node.default_node()
        for impl in list(me.publications.values()):
            impl.close()
            me.remove_publication(impl)
        for impl in list(me.subscriptions.values()):
            impl.close()
            me.remove_subscription(impl)


# ---------------------------------------------------------------------------------------------
# the service manager

class _ServiceHandle:
    """How a rospy service object registered through the manager sits in the node's registry:
    the node calls it for each inbound connection."""

    def __init__(self, service: Any) -> None:
        self.service = service

    def __call__(self, sock: Any, header: Dict[str, str], conn: Any) -> None:
        serve = getattr(self.service, "_handle_connection", None)
        if serve is not None:
            serve(sock, header, conn)
            return
        # a bare service record (rospy.service._Service) has nothing to answer with
        from minros.wire import sockets, tcpros

        name = getattr(self.service, "resolved_name", header.get("service", ""))
        sock.sendall(tcpros.encode_error_header(
            f"[{_node.get_caller_id()}] cannot serve [{name}]: no handler"))
        sockets.close(sock)


def _service_of(handler: Any) -> Any:
    """The service object behind a node registry entry."""
    if isinstance(handler, _ServiceHandle):
        return handler.service
    return getattr(handler, "__self__", handler)


class ServiceManager:
    """Services by resolved name (rospy.service.ServiceManager); one name, one service."""

    def __init__(self, registry: Optional[Dict[str, Any]] = None) -> None:
        self.map: Dict[str, Any] = {} if registry is None else registry
        self.lock = threading.RLock()

    def get_services(self) -> List[Tuple[str, str]]:
        """``[(name, uri), ...]``."""
        with self.lock:
            return [(name, service.uri) for name, service in self.map.items()]

    def unregister_all(self) -> None:
        with self.lock:
            self.map.clear()

    def register(self, resolved_service_name: str, service: Any) -> None:
        """ServiceException when the name is taken."""
        with self.lock:
            if resolved_service_name in self.map:
                raise ServiceException(f"service [{resolved_service_name}] already registered")
            self.map[resolved_service_name] = service
        get_registration_listeners().notify_added(resolved_service_name, service.uri, Registration.SRV)

    def unregister(self, resolved_service_name: str, service: Any) -> None:
        """Unregister ``service`` (nothing when another service has the name)."""
        with self.lock:
            if self.map.get(resolved_service_name) is not service:
                return
            del self.map[resolved_service_name]
        get_registration_listeners().notify_removed(resolved_service_name, service.uri, Registration.SRV)

    def get_service(self, resolved_service_name: str) -> Any:
        with self.lock:
            return self.map.get(resolved_service_name)


class NodeServiceManager(ServiceManager):
    """The node's services (the default service manager): registering puts a service in the
    node's TCPROS server and registers it with the master when the node runs."""

    def __init__(self) -> None:
        super().__init__({})

    @property  # type: ignore[override]
    def map(self) -> Dict[str, Any]:
        return {name: _service_of(h) for name, h in _node.default_node().services.items()}

    @map.setter
    def map(self, value: Dict[str, Any]) -> None:
        pass  # the node's registry is the map

    def get_services(self) -> List[Tuple[str, str]]:
        return [(name, getattr(service, "uri", None)) for name, service in self.map.items()]

    def unregister_all(self) -> None:
        for name in list(_node.default_node().services):
            _node.unregister_service(name)

    def register(self, resolved_service_name: str, service: Any) -> None:
        _node.register_service(resolved_service_name, _ServiceHandle(service))

    def unregister(self, resolved_service_name: str, service: Any) -> None:
        if self.get_service(resolved_service_name) is service:
            _node.unregister_service(resolved_service_name)

    def get_service(self, resolved_service_name: str) -> Any:
        return self.map.get(resolved_service_name)


_topic_manager: Any = TopicManager()
_service_manager: Any = NodeServiceManager()


def get_topic_manager() -> Any:
    return _topic_manager


def set_topic_manager(tm: Any) -> None:
    global _topic_manager
    _topic_manager = tm


def get_service_manager() -> Any:
    return _service_manager


def set_service_manager(sm: Any) -> None:
    global _service_manager
    _service_manager = sm


# ---------------------------------------------------------------------------------------------
# the registration manager

def _proxy(uri: Optional[str]) -> Optional[ServerProxy]:
    try:
        return ServerProxy(uri) if uri else None
    except ValueError:
        return None


class RegManager(RegistrationListener):
    """Keeps the master told of the managers' registrations and connects subscriptions to
    the publishers the master names (rospy's registration manager; a minros node does this
    for itself, so this one serves code that drives rospy's machinery directly)."""

    def __init__(self, handler: Any) -> None:
        self.logger = logging.getLogger("rospy.registration")
        self.handler = handler
        self.uri: Optional[str] = None
        self.master_uri: Optional[str] = None
        self.updates: List[Tuple[str, List[str]]] = []
        self.cond = threading.Condition()
        self.registered = False

    def start(self, uri: Optional[str], master_uri: Optional[str]) -> None:
        """Register everything with the master at ``master_uri`` (until it answers or the node
        shuts down), then :meth:`run`. Nothing to do without a master, or if it is us."""
        self.registered = False
        self.master_uri, self.uri = master_uri, uri
        if not master_uri or master_uri == uri:
            return
        master = _proxy(master_uri)
        caller_id = _node.get_caller_id()
        first = True
        while not self.registered and not is_shutdown():
            try:
                tm, sm = get_topic_manager(), get_service_manager()
                for name, data_type in tm.get_publications():
                    master.registerPublisher(caller_id, name, data_type, uri)
                for name, data_type in tm.get_subscriptions():
                    code, _msg, val = master.registerSubscriber(caller_id, name, data_type, uri)
                    if code == 1:
                        self.publisher_update(name, val)
                for name, service_uri in sm.get_services():
                    master.registerService(caller_id, name, service_uri, uri)
                self.registered = True
                get_registration_listeners().add_listener(self)
            except Exception:
                if first:
                    self.logger.error("Unable to immediately register with master node [%s]: "
                                      "master may not be running yet. Will keep trying.", master_uri)
                    first = False
                _node.wait_for_shutdown(0.2)
        if self.registered:
            self.run()

    def is_registered(self) -> bool:
        return self.registered

    def run(self) -> None:
        """Connect to the publishers of each queued update until the handler or node is done."""
        while not self.handler.done and not is_shutdown():
            with self.cond:
                if not self.updates:
                    self.cond.wait(0.5)
                if not self.updates:
                    continue
                topic, uris = self.updates.pop()
                self.updates = [u for u in self.updates if u[0] != topic]
            for uri in uris:
                threading.Thread(target=self._connect_topic_thread, args=(topic, uri),
                                 daemon=True).start()

    def _connect_topic_thread(self, topic: str, uri: str) -> None:
        try:
            code, msg, _ = self.handler._connect_topic(topic, uri)
            if code != 1:
                self.logger.debug("Unable to connect subscriber to publisher [%s] for topic "
                                  "[%s]: %s", uri, topic, msg)
        except Exception:
            if not is_shutdown():
                self.logger.debug("Unable to connect to publisher [%s] for topic [%s]: %s",
                                  uri, topic, traceback.format_exc())

    def cleanup(self, reason: str) -> None:
        """Unregister everything from the master, in one multicall."""
        with self.cond:
            self.cond.notify_all()
        master = _proxy(self.master_uri)
        if master is None:
            return
        caller_id = _node.get_caller_id()
        get_registration_listeners().clear()
        tm, sm = get_topic_manager(), get_service_manager()
        try:
            multi = xmlrpc.client.MultiCall(master)
            for name, _ in tm.get_subscriptions():
                multi.unregisterSubscriber(caller_id, name, self.uri)
            for name, _ in tm.get_publications():
                multi.unregisterPublisher(caller_id, name, self.uri)
            for name, service_uri in sm.get_services():
                multi.unregisterService(caller_id, name, service_uri)
            multi()
        except Exception as exc:
            self.logger.warning("cannot unregister with master: %s", exc)

    def reg_removed(self, resolved_name: str, data_type_or_uri: str, reg_type: str) -> None:
        master = _proxy(self.master_uri)
        if master is None:
            self.logger.error("Registrar: master_uri is not set yet, cannot inform master of "
                              "deregistration")
            return
        caller_id = _node.get_caller_id()
        try:
            if reg_type == Registration.PUB:
                master.unregisterPublisher(caller_id, resolved_name, self.uri)
            elif reg_type == Registration.SUB:
                master.unregisterSubscriber(caller_id, resolved_name, self.uri)
            elif reg_type == Registration.SRV:
                master.unregisterService(caller_id, resolved_name, data_type_or_uri)
        except Exception:
            self.logger.warning("unable to communicate with ROS Master, registrations are now "
                                "out of sync")

    def reg_added(self, resolved_name: str, data_type_or_uri: str, reg_type: str) -> None:
        master = _proxy(self.master_uri)
        if master is None:
            self.logger.error("Registrar: master_uri is not set yet, cannot inform master of "
                              "registration")
            return
        args = (_node.get_caller_id(), resolved_name, data_type_or_uri, self.uri)
        while not is_shutdown():
            try:
                if reg_type == Registration.PUB:
                    master.registerPublisher(*args)
                elif reg_type == Registration.SUB:
                    code, _msg, val = master.registerSubscriber(*args)
                    if code == 1:
                        self.publisher_update(resolved_name, val)
                elif reg_type == Registration.SRV:
                    master.registerService(*args)
                return
            except Exception:
                _node.wait_for_shutdown(0.2)

    def publisher_update(self, resolved_name: str, uris: List[str]) -> None:
        """Queue a publisher list for :meth:`run`."""
        with self.cond:
            self.updates.append((resolved_name, uris))
            self.cond.notify_all()
