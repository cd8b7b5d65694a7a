"""The Node: one object that owns everything a ROS node is, composed of one small object per
concern (goroslib keeps a file per concern of its Node; here each is an object):

* ``names`` (:class:`NodeNames`): caller id, namespace, remappings, advertised addresses;
* ``lifecycle`` (:class:`Lifecycle`): init once, shutdown hooks, shutdown once;
* ``registries`` (:class:`Registries`): publications, subscriptions, services, parameters;
* ``registration`` (:class:`Registration`): those registered with the master, again after
  a master restart, undone with one multicall;
* ``master`` (:class:`MasterClient`): the typed Master API, as this node;
* ``connections`` (:class:`Connections`): the transports the node speaks
  (:mod:`minros.transport`, TCPROS last) and the TCPROS server, which hands each inbound
  connection to what its header names;
* the slave API (:class:`SlaveApi` on an XML-RPC server).

The Node wires them together and is their façade: its methods are the node's API, each one
the concern's. Lock order where locks nest: ``registration.lock`` (held across one exchange
with the master) -> ``registries.lock`` (a leaf), and ``registration.lock`` -> the lock of
``connections`` (a service's registration starts the TCPROS server); the lifecycle's lock is
a leaf too.
"""

from __future__ import annotations

import logging
import sys
import traceback
from typing import Any, Callable, Dict, List, Sequence, Set, Tuple

from minros import names, rosenv
from minros.exceptions import ROSException, ROSInitException
from minros.node.connections import Connections
from minros.node.lifecycle import Lifecycle
from minros.node.names import NodeNames
from minros.node.registration import Registration
from minros.node.registries import (
    ParamUpdateHandler,
    Publication,
    Registries,
    ServiceHandler,
    Subscription,
)
from minros.node.slave_api import SlaveApi
from minros.node.tcpros_server import TCPROSServer
from minros.transport.base import ProtocolHandler, Transport
from minros.wire import trace
from minros.wire.masterapi import MasterClient, RemoteError
from minros.wire.xmlrpc import XmlRpcServer

__all__ = ["XMLRPC_TIMEOUT", "Node"]

#: timeout of XML-RPC calls to the master and to other nodes
XMLRPC_TIMEOUT = 10.0

_logger = logging.getLogger("minros.node")


class Node:
    """One ROS node: names, lifecycle, registries, master registration and servers."""

    def __init__(self, argv: Sequence[str] | None = None) -> None:
        self.names = NodeNames(list(sys.argv if argv is None else argv))
        self.lifecycle = Lifecycle(self.close)
        self.registries = Registries()
        self.master = MasterClient(lambda: self.names.master_uri, lambda: self.names.caller_id,
                                   XMLRPC_TIMEOUT)
        self.registration = Registration(self.master, self.registries, self.lifecycle,
                                         lambda: self.uri, self.rosrpc_uri)
        self.connections = Connections(self.names, self.registries, self.is_shutdown_requested,
                                       lambda: self.registration.started)
        #: the transports this node speaks, in the order a subscriber offers them
        self.protocols: List[ProtocolHandler] = self.connections.protocols
        self.uri: str | None = None  # the slave API's, once started
        self._xmlrpc: XmlRpcServer | None = None
        self._xmlrpc_port = 0  # 0: any free port

    # -- names -------------------------------------------------------------------------------

    @property
    def caller_id(self) -> str:
        return self.names.caller_id

    name = caller_id

    @property
    def master_uri(self) -> str:
        return self.names.master_uri

    def get_namespace(self) -> str:
        return self.names.get_namespace()

    def get_mappings(self) -> Dict[str, str]:
        return self.names.get_mappings()

    def resolve_name(self, name: str, caller_id: str | None = None) -> str:
        return self.names.resolve_name(name, caller_id)

    def resolve_name_without_node_name(self, name: str) -> str:
        return self.names.resolve_name_without_node_name(name)

    def resolve_topic_name(self, name: str) -> str:
        return self.names.resolve_topic_name(name)

    def remap_name(self, name: str, caller_id: str | None = None) -> str:
        return self.names.remap_name(name, caller_id)

    # -- lifecycle ---------------------------------------------------------------------------

    @property
    def initialized(self) -> bool:
        return self.lifecycle.initialized

    @property
    def init_args(self) -> Tuple[Any, ...] | None:
        return self.lifecycle.init_args

    def is_shutdown(self) -> bool:
        return self.lifecycle.is_shutdown()

    def is_shutdown_requested(self) -> bool:
        return self.lifecycle.is_shutdown_requested()

    def wait_for_shutdown(self, timeout: float | None) -> bool:
        return self.lifecycle.wait_for_shutdown(timeout)

    def on_shutdown(self, hook: Callable[[], Any]) -> None:
        self.lifecycle.on_shutdown(hook)

    def add_shutdown_hook(self, hook: Callable[[str], Any]) -> None:
        self.lifecycle.add_shutdown_hook(hook)

    def signal_shutdown(self, reason: str) -> None:
        self.lifecycle.signal_shutdown(reason)

    def spin(self) -> None:
        self.lifecycle.spin()

    def init(self, name: str, argv: Sequence[str] | None = None, anonymous: bool = False,
             xmlrpc_port: int = 0, tcpros_port: int = 0, args_key: Tuple[Any, ...] = ()) -> bool:
        """Name the node, start its servers and register it (the network half of
        ``rospy.init_node``). False when it was already initialised with the same
        ``args_key``; ROSException when with different ones."""
        if not name:
            raise ValueError("name must not be empty")
        if names.SEP in name:
            raise ValueError("namespaces are not allowed in node names")
        if not self.lifecycle.claim_init(args_key):
            return False
        argv_list = list(sys.argv if argv is None else argv)
        self.names.name_node(name, argv_list, argv is not None, anonymous)
        self._xmlrpc_port, self.connections.port = xmlrpc_port, tcpros_port
        self.start()
        if self.is_shutdown_requested():
            raise ROSInitException("init_node interrupted before it could complete")
        # private parameters from the command line (_name:=value, YAML-typed)
        try:
            params = names.load_command_line_node_params(argv_list)
        except ValueError as exc:
            raise ROSInitException(str(exc)) from None
        for key, value in params.items():
            try:
                self.master.set_param(names.ns_join(self.caller_id, key), value)
            except RemoteError as exc:
                raise ROSInitException(f"cannot set parameter [{key}]: {exc}") from None
        self.lifecycle.initialized = True  # as rospy: before /rosout and /clock are set up
        return True

    def start(self) -> None:
        """Start the slave API, register everything with the master, watch the master."""
        self.connections.host = self.names.host_name()
        try:
            self.connections.allowed = rosenv.allowed_hosts()
        except ValueError as exc:
            raise ROSInitException(str(exc)) from None
        self._xmlrpc = XmlRpcServer(SlaveApi(self), host=self.names.bind_address(),
                                    port=self._xmlrpc_port, allowed=self.connections.allowed,
                                    on_refused=TCPROSServer.refused,
                                    what=f"node [{self.caller_id}]")
        self._xmlrpc.start()
        self.uri = f"http://{self.connections.host}:{self._xmlrpc.port}/"
        _logger.info("ROS Slave URI: [%s]", self.uri)
        trace.set_node(self.caller_id, self.uri, self.master_uri)
        self.registration.started = True
        if self.connections.port:
            self.tcpros_address()
        self.registration.register_all(first=True)
        self.registration.start_probe()

    def close(self) -> None:
        """Unregister everything with one multicall, close every connection, stop the servers."""
        if self.registration.closed.is_set():
            return
        self.registration.unregister_all(
            lambda: self.rosrpc_uri() if self.connections.server is not None else None)
        if not self.registration.started:
            return
        pubs, subs = self.registries.endpoints()
        endpoints: List[Publication | Subscription] = [*pubs, *subs]
        for endpoint in endpoints:
            try:
                endpoint.close()
            except Exception:
                _logger.debug("close failed: %s", traceback.format_exc())
        self.connections.close()
        if self._xmlrpc is not None:
            self._xmlrpc.shutdown()

    # -- connections --------------------------------------------------------------------------

    @property
    def host(self) -> str:
        return self.connections.host

    def tcpros_address(self) -> Tuple[str, int]:
        """(advertised host, port) of the node's TCPROS server (started on first use)."""
        return self.connections.tcpros_address()

    @property
    def tcpros_server(self) -> TCPROSServer | None:
        return self.connections.server

    def rosrpc_uri(self) -> str:
        """The ``rosrpc://host:port`` URI of the node's services."""
        host, port = self.tcpros_address()
        return f"rosrpc://{host}:{port}"

    def answer_protocol(self, topic: str, offer: Any) -> List[Any] | None:
        """requestTopic: the answer to one offered protocol, None if we do not speak it."""
        return self.connections.answer_protocol(topic, offer)

    def local_transport(self, topic: str, pub_uri: str, data_class: Any,
                        fields: Dict[str, str]) -> Transport | None:
        """The subscriber's end of an intra-process link when ``pub_uri`` is this node (see
        :meth:`Connections.local_transport`); else None."""
        if pub_uri != self.uri:
            return None
        return self.connections.local_transport(topic, data_class, fields)

    # -- what the node offers and asks for ---------------------------------------------------

    @property
    def publications(self) -> Dict[str, Publication]:
        return self.registries.publications

    @property
    def subscriptions(self) -> Dict[str, Subscription]:
        return self.registries.subscriptions

    @property
    def services(self) -> Dict[str, ServiceHandler]:
        return self.registries.services

    @property
    def param_subscriptions(self) -> Set[str]:
        return self.registries.param_subscriptions

    def add_publication(self, pub: Publication, announce: bool = True) -> None:
        self.registries.add_publication(pub)
        if announce:
            self.registration.announce_publication(pub)

    def remove_publication(self, pub: Publication) -> None:
        if self.registries.remove_publication(pub):
            self.registration.withdraw_publication(pub.resolved_name)

    def add_subscription(self, sub: Subscription, announce: bool = True) -> None:
        self.registries.add_subscription(sub)
        if announce:
            self.registration.announce_subscription(sub)

    def remove_subscription(self, sub: Subscription) -> None:
        if self.registries.remove_subscription(sub):
            self.registration.withdraw_subscription(sub.resolved_name)

    def register_service(self, resolved_name: str, handler: ServiceHandler) -> None:
        """Serve ``resolved_name``: ``handler(stream, header, conn)`` gets every inbound
        connection naming it (see ServiceHandler). ServiceException if served already."""
        self.registries.add_service(resolved_name, handler)
        self.registration.announce_service(resolved_name)

    def unregister_service(self, resolved_name: str) -> None:
        if self.registries.remove_service(resolved_name):
            self.registration.withdraw_service(resolved_name)

    def subscribe_param(self, resolved_key: str) -> Any:
        """subscribeParam with the master; later paramUpdate calls go to the handlers. Returns
        the current value (``{}`` when unset, as the master answers)."""
        if not self.registration.started:
            raise ROSInitException("client code must call rospy.init_node() first")
        try:
            return self.registration.subscribe_param(resolved_key)
        except RemoteError as exc:
            raise ROSException(f"cannot subscribe to parameter [{resolved_key}]: {exc}") from None

    def add_param_update_handler(self, handler: ParamUpdateHandler) -> None:
        """``handler(key, value) -> bool`` is called for every slave paramUpdate."""
        self.registries.add_param_update_handler(handler)
