"""actionlib.status_tracker: StatusTracker (minros.actionlib)."""

from minros.actionlib import StatusTracker  # noqa: F401
