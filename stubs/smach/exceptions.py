"""smach.exceptions stand-in (see minros.smach.exceptions)."""

from minros.smach.exceptions import *  # noqa: F401,F403
