"""actionlib stand-in: the action library served by minros.actionlib."""

from actionlib import (  # noqa: F401,E402 - the submodules scripts import by name
    action_client,
    action_server,
    exceptions,
    goal_id_generator,
    handle_tracker_deleter,
    server_goal_handle,
    simple_action_client,
    simple_action_server,
    status_tracker,
)
from minros.actionlib import *  # noqa: F401,F403
from minros.actionlib import __all__ as __all__  # noqa: PLC0414
from std_msgs.msg import Header  # noqa: E402,F401 - actionlib's package has it (from its client)


def __getattr__(name: str):
    if name == "g_goal_id":
        return action_client.g_goal_id
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
