"""smach_ros stand-in: smach's ROS states, action wrapper and introspection (see minros.smach_ros)."""

from minros.smach_ros import *  # noqa: F401,F403
from minros.smach_ros import __all__ as __all__  # noqa: PLC0414
from smach_ros import (  # noqa: F401,E402 - the submodules scripts import by name
    action_server_wrapper,
    condition_state,
    introspection,
    monitor_state,
    service_state,
    simple_action_state,
    util,
)
