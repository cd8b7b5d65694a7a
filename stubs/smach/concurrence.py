"""smach.concurrence stand-in (see minros.smach.concurrence)."""

from minros.smach.concurrence import *  # noqa: F401,F403
