"""actionlib for minros: preemptable goals over the ROS action protocol.

The ``actionlib`` stand-in package re-exports this one, so ``import actionlib`` in an
unmodified node gives :class:`SimpleActionClient`, :class:`SimpleActionServer`,
:class:`ActionClient`, :class:`ActionServer` and their goal handles. The protocol is actionlib's:
five topics per action (goal, cancel, status, feedback, result) carrying the seven types
generated from the ``.action`` file, so minros and ROS 1 nodes drive each other's actions.

* :mod:`.states` - the client and server state machines as data (pure functions)
* :mod:`.client` / :mod:`.simple_client` - ActionClient, SimpleActionClient
* :mod:`.server` / :mod:`.simple_server` - ActionServer, SimpleActionServer
"""

from __future__ import annotations

from actionlib_msgs.msg import GoalID, GoalStatus, GoalStatusArray

from .client import (
    ActionClient,
    ActionException,
    ClientGoalHandle,
    CommStateMachine,
    GoalManager,
)
from .server import (
    ActionServer,
    GoalIDGenerator,
    HandleTrackerDeleter,
    ServerGoalHandle,
    StatusTracker,
    nop_cb,
)
from .simple_client import SimpleActionClient
from .simple_server import SimpleActionServer
from .states import (
    INVALID_TRANSITION,
    NO_TRANSITION,
    CommState,
    GoalStatusCodes,
    SimpleGoalState,
    TerminalState,
    get_name_of_constant,
)

# actionlib adds to_string to GoalStatus, and code logs states with it
GoalStatus.to_string = classmethod(lambda cls, n: GoalStatusCodes.to_string(n))

__all__ = [
    "ActionClient", "ActionException", "ActionServer", "ClientGoalHandle", "CommState",
    "CommStateMachine", "GoalID", "GoalIDGenerator", "GoalManager", "GoalStatus",
    "GoalStatusArray", "HandleTrackerDeleter", "INVALID_TRANSITION", "NO_TRANSITION",
    "ServerGoalHandle", "SimpleActionClient", "SimpleActionServer", "SimpleGoalState",
    "StatusTracker", "TerminalState", "get_name_of_constant", "nop_cb",
]
