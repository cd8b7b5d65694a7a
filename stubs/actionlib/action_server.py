"""actionlib.action_server: ActionServer (minros.actionlib)."""

from actionlib_msgs.msg import GoalID, GoalStatus, GoalStatusArray  # noqa: F401
from minros.actionlib import (  # noqa: F401
    ActionException,
    ActionServer,
    GoalIDGenerator,
    HandleTrackerDeleter,
    ServerGoalHandle,
    StatusTracker,
    nop_cb,
)
