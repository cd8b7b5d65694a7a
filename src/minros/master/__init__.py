"""The ROS master: Master API, Parameter Server API and callbacks to nodes.

``python -m minros.master [-p PORT]`` runs it like ``rosmaster --core`` (no rosout, no roscore
parameters; ``minros core`` adds those).

The modules, from pure to I/O (each imports only those above it in this list; the contract
"The master: ..." in pyproject.toml keeps the order):

* :mod:`.registrations` — :class:`Registrations` / :class:`RegistrationManager`: publishers,
  subscribers, services, parameter subscriptions and the node table (same name + new URI bumps
  the old node); pure;
* :mod:`.params` — :class:`ParamTree`, the parameter dictionary (nested dicts keyed by resolved
  names), :func:`compute_param_updates`, which decides who gets which ``paramUpdate``, and
  :class:`ParamDictionary`, the two with the subscriptions (rosmaster.paramserver's shape); pure;
* :mod:`.log` — the master's log (``+PUB``, ``-SUB``, ``+PARAM`` ... as in rosmaster's
  master.log), silent until :func:`configure_log_file` is called;
* :mod:`.callbacks` — :class:`CallbackPool`: asynchronous ``publisherUpdate`` / ``paramUpdate``
  / ``shutdown`` calls to nodes: a few worker threads, at most one call in flight per node and
  calls to one node in order, each call bounded by a timeout; a slow or dead node never delays
  an API reply;
* :mod:`.handler` — :class:`MasterHandler`: the XML-RPC methods with rosmaster's argument
  validation and exact ``[code, statusMessage, value]`` results, plus one minros extension:
  ``subscribeGraph`` / ``unsubscribeGraph``, after which the master calls
  ``graphUpdate(caller_id, version)`` on the subscriber's URI whenever a registration changes
  (``minros web`` pushes its graph that way; against rosmaster, which has no such method, it
  polls);
* :mod:`.server` — :class:`Master` (handler + :class:`minros.wire.xmlrpc.XmlRpcServer`) and
  :func:`main`, the ``rosmaster --core`` command.

This package re-exports the names of all six, so ``from minros.master import Master`` and the
like keep working; the stand-ins under ``stubs/rosmaster/`` import each from its own module, as
rosmaster's modules split the same way.
"""

from minros.master.callbacks import (
    CALLBACK_TIMEOUT,
    CALLBACK_WORKERS,
    COALESCE_BACKLOG,
    MAX_QUEUED_PER_NODE,
    CallbackPool,
)
from minros.master.handler import MAX_GRAPH_WATCHERS, MasterHandler
from minros.master.log import configure_log_file
from minros.master.log import log as _log  # noqa: F401 - minros core writes to it too
from minros.master.params import ParamDictionary, ParamTree, compute_param_updates
from minros.master.registrations import (
    Caller,
    InternalException,
    NodeRef,
    RegistrationManager,
    Registrations,
)
from minros.master.server import DEFAULT_MASTER_PORT, Master, install_stop_signals, main

__all__ = [
    "CALLBACK_TIMEOUT", "CALLBACK_WORKERS", "COALESCE_BACKLOG", "DEFAULT_MASTER_PORT",
    "MAX_GRAPH_WATCHERS", "MAX_QUEUED_PER_NODE", "Caller", "CallbackPool", "InternalException",
    "Master", "MasterHandler", "NodeRef", "ParamDictionary", "ParamTree", "RegistrationManager",
    "Registrations", "compute_param_updates", "configure_log_file",
    "install_stop_signals", "main",
]
