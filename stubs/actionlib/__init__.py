"""actionlib stand-in: the action library served by minros.actionlib."""

import threading  # noqa: F401 - see __all__
import time  # noqa: F401
import traceback  # noqa: F401
import weakref  # noqa: F401

import rospy  # noqa: F401
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
from minros.actionlib import __all__ as _minros_all
from std_msgs.msg import Header  # noqa: E402,F401 - actionlib's package has it (from its client)

#: what ``from actionlib import *`` gives in ROS: its package has no __all__ and star-imports its
#: four modules, so their public names come along, the modules they import (threading, rospy,
#: ...) included; smach_ros's ``from actionlib import *`` then uses ``threading``
__all__ = [*_minros_all, "Header", "g_goal_id", "rospy", "threading", "time", "traceback",  # noqa: F405
           "weakref", "action_client", "action_server", "exceptions", "goal_id_generator",
           "handle_tracker_deleter", "server_goal_handle", "simple_action_client",
           "simple_action_server", "status_tracker"]


def __getattr__(name: str):
    if name == "g_goal_id":
        return action_client.g_goal_id
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
