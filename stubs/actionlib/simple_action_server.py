"""actionlib.simple_action_server: SimpleActionServer (minros.actionlib)."""

from minros.actionlib import SimpleActionServer  # noqa: F401
