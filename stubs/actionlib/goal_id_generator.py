"""actionlib.goal_id_generator: GoalIDGenerator (minros.actionlib)."""

from actionlib_msgs.msg import GoalID  # noqa: F401
from minros.actionlib import GoalIDGenerator  # noqa: F401


def __getattr__(name: str):
    if name == "s_goalcount":  # goal ids generated so far in this process
        return GoalIDGenerator.issued
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
