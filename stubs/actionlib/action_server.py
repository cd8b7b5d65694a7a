"""actionlib.action_server: ActionServer (minros.actionlib)."""

from minros.actionlib import ActionServer, nop_cb  # noqa: F401
