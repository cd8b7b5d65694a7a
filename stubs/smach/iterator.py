"""smach.iterator stand-in (see minros.smach.iterator)."""

from minros.smach.iterator import *  # noqa: F401,F403
