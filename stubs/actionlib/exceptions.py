"""actionlib.exceptions: ActionException (minros.actionlib)."""

from minros.actionlib import ActionException  # noqa: F401
