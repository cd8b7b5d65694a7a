"""smach.state stand-in (see minros.smach.state)."""

from minros.smach.state import *  # noqa: F401,F403
