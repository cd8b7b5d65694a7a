"""The node runtime: one :class:`Node` object owns everything a ROS node is.

A node is a name with remappings, a lifecycle (init, shutdown hooks, shutdown), what it offers
and asks for (publications, subscriptions, services, parameter subscriptions), the master it
registers those with, and two servers: the slave XML-RPC API and one TCPROS server that hands
inbound connections to the publication or service they name. ``core.py`` composes them, one
module per concern: ``names``, ``lifecycle``, ``registries``, ``registration``,
``tcpros_server``, ``slave_api``.

A process is one node, as in rospy: the module-level functions here (``get_caller_id``,
``is_shutdown``, ``signal_shutdown``, ...) are rospy's API and delegate to the process's
default Node, which exists from import on (named ``<ns>/unnamed`` until ``init_node``). Tests
make Node objects of their own and drive registration, master restarts and shutdown in-process.
"""

from __future__ import annotations

import atexit
import sys
from typing import Any, Callable, Dict, List, Tuple

import minros.names as _graph_names  # not `names`: the package's submodule of that name wins
from minros import rosenv
from minros.node.core import XMLRPC_TIMEOUT, Node
from minros.node.registries import ParamUpdateHandler, Publication, ServiceHandler, Subscription
from minros.node.slave_api import SlaveApi
from minros.wire.masterapi import MasterClient

__all__ = [
    "DEFAULT_MASTER_URI",
    "XMLRPC_TIMEOUT",
    "Node",
    "ParamUpdateHandler",
    "Publication",
    "ServiceHandler",
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
    return _graph_names.strip_remapping_args(sys.argv if argv is None else argv)


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


def register_service(resolved_name: str, handler: ServiceHandler) -> None:
    _default.register_service(resolved_name, handler)


def unregister_service(resolved_name: str) -> None:
    _default.unregister_service(resolved_name)


def subscribe_param(resolved_key: str) -> Any:
    return _default.subscribe_param(resolved_key)


def add_param_update_handler(handler: ParamUpdateHandler) -> None:
    _default.add_param_update_handler(handler)
