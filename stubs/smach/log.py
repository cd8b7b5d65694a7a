"""smach.log stand-in (see minros.smach.log)."""

from minros.smach.log import *  # noqa: F401,F403
