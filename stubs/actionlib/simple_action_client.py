"""actionlib.simple_action_client: SimpleActionClient (minros.actionlib)."""

from minros.actionlib import SimpleActionClient, SimpleGoalState  # noqa: F401
