"""rosmaster.registrations: publishers, subscribers, services, parameter subscriptions and
the node table (minros.master.registrations)."""

from __future__ import annotations

from typing import Any

from minros.master import registrations as _registrations
from minros.master.registrations import NodeRef, Registrations  # noqa: F401


def shutdown_node_task(api: str, caller_id: str, reason: str) -> None:
    """Ask the node at ``api`` to shut down (bounded; a dead node is no error)."""
    from minros.tools.master import TOOL_TIMEOUT
    from minros.wire.slaveapi import RemoteError, SlaveClient

    try:
        with SlaveClient(api, "/master", timeout=TOOL_TIMEOUT) as node:
            node.shutdown(f"[{caller_id}] Reason: {reason}")
    except (OSError, RemoteError):
        pass


class RegistrationManager(_registrations.RegistrationManager):
    """rosmaster's constructor: a node that registers again from a new URI has its old process
    told to shut down through ``thread_pool.queue_task(api, task, args)``."""

    def __init__(self, thread_pool: Any) -> None:
        def bump(old_api: str, caller_id: str) -> None:
            thread_pool.queue_task(old_api, shutdown_node_task,
                                   (old_api, caller_id, "new node registered with same name"))
        super().__init__(on_bump=bump)
        self.thread_pool = thread_pool

from rosmaster.util import remove_server_proxy, xmlrpcapi  # noqa: E402, F401
