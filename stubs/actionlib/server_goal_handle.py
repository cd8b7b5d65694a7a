"""actionlib.server_goal_handle: ServerGoalHandle (minros.actionlib)."""

from minros.actionlib import ServerGoalHandle  # noqa: F401
