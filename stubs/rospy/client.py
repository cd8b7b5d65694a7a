"""rospy.client: node life-cycle functions (minros.client.init, minros.node, minros.client.topics),
parameters (minros.client.params), the log levels, and the roscpp logger messages rospy's module
imports (built on first use)."""

from typing import Any

from minros.client.init import init_node  # noqa: F401
from minros.client.log import DEBUG, ERROR, FATAL, INFO, WARN, logdebug, logerr, loginfo, logwarn  # noqa: F401
from minros.client.msproxy import get_master  # noqa: F401
from minros.client.params import (  # noqa: F401
    delete_param,
    get_param,
    get_param_cached,
    get_param_names,
    has_param,
    search_param,
    set_param,
)
from minros.client.services import Service  # noqa: F401
from minros.client.topics import get_published_topics, wait_for_message  # noqa: F401
from minros.node import myargv, on_shutdown, spin  # noqa: F401
from minros.rospy_internals.client import load_command_line_node_params  # noqa: F401, E402

TIMEOUT_READY = 15.0  # seconds rospy waits for the node to be ready

#: message classes rospy.client imports, by the type they are generated from
_MESSAGES = {"Log": "rosgraph_msgs/Log", "Logger": "roscpp/Logger"}
_SERVICES = {"GetLoggers": "roscpp/GetLoggers", "SetLoggerLevel": "roscpp/SetLoggerLevel"}


def __getattr__(name: str) -> Any:
    from minros.msgs import get_message_class, get_service_class

    if name in _MESSAGES:
        return get_message_class(_MESSAGES[name])
    if name in _SERVICES:
        return get_service_class(_SERVICES[name])
    if name.endswith("Response") and name[:-len("Response")] in _SERVICES:
        return get_service_class(_SERVICES[name[:-len("Response")]])._response_class
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
