"""actionlib.simple_action_server: SimpleActionServer (minros.actionlib)."""

from actionlib_msgs.msg import GoalStatus  # noqa: F401
from minros.actionlib import (  # noqa: F401
    ActionServer,
    ServerGoalHandle,
    SimpleActionServer,
    nop_cb,
)
