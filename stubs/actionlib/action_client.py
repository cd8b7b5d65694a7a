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
