"""actionlib.handle_tracker_deleter: HandleTrackerDeleter (minros.actionlib)."""

from minros.actionlib import HandleTrackerDeleter  # noqa: F401
