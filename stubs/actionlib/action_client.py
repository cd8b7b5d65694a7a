"""actionlib.action_client: ActionClient and the client-side goal state (minros.actionlib)."""

from actionlib_msgs.msg import GoalID, GoalStatus, GoalStatusArray  # noqa: F401
from minros.actionlib import (  # noqa: F401
    INVALID_TRANSITION,
    NO_TRANSITION,
    ActionClient,
    ActionException,
    ClientGoalHandle,
    CommState,
    CommStateMachine,
    GoalManager,
    TerminalState,
    get_name_of_constant,
)
from std_msgs.msg import Header  # noqa: F401 - actionlib's module imports it (from rospy)


def __getattr__(name: str):
    if name == "g_goal_id":  # the number the next client goal id carries
        from minros.actionlib.client import next_goal_number

        return next_goal_number()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
