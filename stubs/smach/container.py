"""smach.container stand-in (see minros.smach.container)."""

from minros.smach.container import *  # noqa: F401,F403
