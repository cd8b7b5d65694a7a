"""actionlib.simple_action_client: SimpleActionClient (minros.actionlib)."""

from actionlib_msgs.msg import GoalStatus  # noqa: F401
from minros.actionlib import (  # noqa: F401
    ActionClient,
    CommState,
    SimpleActionClient,
    SimpleGoalState,
    get_name_of_constant,
)
