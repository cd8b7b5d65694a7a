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
from functools import partial
from typing import Any, Callable, Dict, List, Optional, Tuple

from minros import node as _node
from minros.client import topics as _topics
from minros.exceptions import ServiceException
from minros.wire.masterapi import MasterClient, RemoteError
from minros.wire.rosapi import unwrap

from .core import (  # noqa: F401 - rospy.impl.registration's namespace has them
    add_preshutdown_hook,
    is_shutdown_requested,
    logdebug,
    logerr,
    logfatal,
    loginfo,
    logwarn,
    signal_shutdown,
    xmlrpcapi,
)
from .names import get_caller_id, get_namespace  # noqa: F401

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
        if reg_type == Registration.PUB:
            return _topics.acquire_publication(resolved_name, data_class)
        if reg_type == Registration.SUB:
            return _topics.acquire_subscription(resolved_name, data_class)
        raise TypeError(f"invalid reg_type: {reg_type}")

    def release_impl(self, reg_type: str, resolved_name: str) -> None:
        impl = self.get_impl(reg_type, resolved_name)
        if impl is not None:
            _topics.release(impl)

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
        for pub in list(me.publications.values()):
            pub.close()
            me.remove_publication(pub)
        for sub in list(me.subscriptions.values()):
            sub.close()
            me.remove_subscription(sub)


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
        uri = service.uri
        with self.lock:
            if self.map.get(resolved_service_name) is not service:
                return
            del self.map[resolved_service_name]
        get_registration_listeners().notify_removed(resolved_service_name, uri, Registration.SRV)

    def get_service(self, resolved_service_name: str) -> Any:
        with self.lock:
            return self.map.get(resolved_service_name)


class NodeServiceManager(ServiceManager):
    """The node's services (the default service manager): registering puts a service in the
    node's TCPROS server and registers it with the master when the node runs."""

    def __init__(self) -> None:
        super().__init__({})

    @property
    def map(self) -> Dict[str, Any]:
        return {name: _service_of(h) for name, h in _node.default_node().services.items()}

    @map.setter
    def map(self, value: Dict[str, Any]) -> None:
        pass  # the node's registry is the map

    def get_services(self) -> List[Tuple[str, str]]:
        return [(name, getattr(service, "uri", None) or "") for name, service in self.map.items()]

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

def _master(uri: Optional[str]) -> Optional[MasterClient]:
    """The master at ``uri`` as this node (None without a URI)."""
    return MasterClient(uri, _node.get_caller_id) if uri else None


class RegManager(RegistrationListener):
    """Keeps the master told of the managers' registrations and connects subscriptions to
    the publishers the master names (rospy's registration manager; a minros node's own is
    :class:`minros.node.registration.Registration`, so this one serves code that drives
    rospy's machinery directly). It calls the master through the one master client."""

    def __init__(self, handler: Any) -> None:
        self.logger = logging.getLogger("rospy.registration")
        self.handler = handler
        self.uri: Optional[str] = None
        self.master_uri: Optional[str] = None
        self.updates: List[Tuple[str, List[str]]] = []
        self.cond = threading.Condition()
        self.registered = False

    def _refused(self, what: str, name: str, call: Callable[[], Any]) -> Any:
        """``call()``'s value; None when the master refused it (logged, as rospy logs it)."""
        try:
            return call()
        except RemoteError as exc:
            self.logger.error("master refused to register %s [%s]: %s", what, name, exc)
            return None

    def start(self, uri: Optional[str], master_uri: Optional[str]) -> None:
        """Register everything with the master at ``master_uri`` (until it answers or the node
        shuts down), then :meth:`run`. Nothing to do without a master, or if it is us."""
        self.registered = False
        self.master_uri, self.uri = master_uri, uri
        if not master_uri or master_uri == uri:
            return
        master = _master(master_uri)
        assert master is not None
        node_uri = uri or ""
        first = True
        while not self.registered and not is_shutdown():
            try:
                tm, sm = get_topic_manager(), get_service_manager()
                for name, data_type in tm.get_publications():
                    self._refused("pub", name, partial(master.register_publisher, name,
                                                       data_type, node_uri))
                for name, data_type in tm.get_subscriptions():
                    publishers = self._refused("sub", name, partial(
                        master.register_subscriber, name, data_type, node_uri))
                    if publishers is not None:
                        self.publisher_update(name, publishers)
                for name, service_uri in sm.get_services():
                    self._refused("srv", name, partial(master.register_service, name,
                                                       service_uri, node_uri))
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
            unwrap(self.handler._connect_topic(topic, uri))  # rospy's slave-side triplet
        except RemoteError as exc:
            self.logger.debug("Unable to connect subscriber to publisher [%s] for topic "
                              "[%s]: %s", uri, topic, exc)
        except Exception:
            if not is_shutdown():
                self.logger.debug("Unable to connect to publisher [%s] for topic [%s]: %s",
                                  uri, topic, traceback.format_exc())

    def cleanup(self, reason: str) -> None:
        """Unregister everything from the master, in one multicall."""
        with self.cond:
            self.cond.notify_all()
        master = _master(self.master_uri)
        if master is None:
            return
        caller_id = master.caller_id
        get_registration_listeners().clear()
        tm, sm = get_topic_manager(), get_service_manager()
        calls = [{"methodName": "unregisterSubscriber", "params": [caller_id, name, self.uri]}
                 for name, _ in tm.get_subscriptions()]
        calls += [{"methodName": "unregisterPublisher", "params": [caller_id, name, self.uri]}
                  for name, _ in tm.get_publications()]
        calls += [{"methodName": "unregisterService", "params": [caller_id, name, service_uri]}
                  for name, service_uri in sm.get_services()]
        if not calls:
            return
        try:
            master.multicall(calls)
        except Exception as exc:
            self.logger.warning("cannot unregister with master: %s", exc)
        finally:
            master.close()

    def reg_removed(self, resolved_name: str, data_type_or_uri: str, reg_type: str) -> None:
        master = _master(self.master_uri)
        if master is None:
            self.logger.error("Registrar: master_uri is not set yet, cannot inform master of "
                              "deregistration")
            return
        uri = self.uri or ""
        try:
            if reg_type == Registration.PUB:
                master.unregister_publisher(resolved_name, uri)
            elif reg_type == Registration.SUB:
                master.unregister_subscriber(resolved_name, uri)
            elif reg_type == Registration.SRV:
                master.unregister_service(resolved_name, data_type_or_uri)
        except Exception:
            self.logger.warning("unable to communicate with ROS Master, registrations are now "
                                "out of sync")
        finally:
            master.close()

    def reg_added(self, resolved_name: str, data_type_or_uri: str, reg_type: str) -> None:
        master = _master(self.master_uri)
        if master is None:
            self.logger.error("Registrar: master_uri is not set yet, cannot inform master of "
                              "registration")
            return
        uri = self.uri or ""
        try:
            while not is_shutdown():
                try:
                    if reg_type == Registration.PUB:
                        self._refused("pub", resolved_name, lambda: master.register_publisher(
                            resolved_name, data_type_or_uri, uri))
                    elif reg_type == Registration.SUB:
                        publishers = self._refused("sub", resolved_name, lambda: master.register_subscriber(
                            resolved_name, data_type_or_uri, uri))
                        if publishers is not None:
                            self.publisher_update(resolved_name, publishers)
                    elif reg_type == Registration.SRV:
                        self._refused("srv", resolved_name, lambda: master.register_service(
                            resolved_name, data_type_or_uri, uri))
                    return
                except Exception:  # the master is unreachable: try again
                    _node.wait_for_shutdown(0.2)
        finally:
            master.close()

    def publisher_update(self, resolved_name: str, uris: List[str]) -> None:
        """Queue a publisher list for :meth:`run`."""
        with self.cond:
            self.updates.append((resolved_name, uris))
            self.cond.notify_all()
