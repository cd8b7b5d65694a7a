"""dynamic_reconfigure for minros: change a node's parameters while it runs.

The ``dynamic_reconfigure`` stand-in re-exports this package. A node describes its tunable
parameters in a ``.cfg`` script (:mod:`.generator` turns it into ``<pkg>.cfg.<Name>Config`` on
import, no build step), serves them with :class:`~.server.Server`, and other nodes change them
with :class:`~.client.Client` or ``rosrun dynamic_reconfigure dynparam`` (:mod:`.dynparam`).
The topics, service and messages are ROS 1's, so ROS 1's dynparam and rqt_reconfigure drive a
minros server and the other way round.
"""

from __future__ import annotations

from typing import Any, List


class DynamicReconfigureException(Exception):
    """Base of dynamic_reconfigure's errors."""


class DynamicReconfigureParameterException(DynamicReconfigureException):
    """A parameter is unknown or its value cannot take the parameter's type."""


class DynamicReconfigureCallbackException(DynamicReconfigureException):
    """The server's callback failed (or returned no configuration)."""


def find_reconfigure_services() -> List[str]:
    """The namespaces of every dynamic_reconfigure server (services ending in /set_parameters)."""
    from minros import node
    from minros.exceptions import ROSException
    from minros.wire.masterapi import RemoteError

    try:
        services = node.master().get_system_state().services
    except RemoteError as exc:
        raise ROSException(f"cannot get the system state from the master: {exc}") from None
    suffix = "/set_parameters"
    return sorted(name[:-len(suffix)] for name, _providers in services if name.endswith(suffix))


def get_parameter_names(descr: Any) -> Any:
    """The parameter names of a configuration type."""
    return descr.defaults.keys()
