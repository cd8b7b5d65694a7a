"""actionlib.goal_id_generator: GoalIDGenerator (minros.actionlib)."""

from minros.actionlib import GoalIDGenerator  # noqa: F401
