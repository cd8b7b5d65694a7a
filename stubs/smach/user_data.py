"""smach.user_data stand-in (see minros.smach.user_data)."""

from minros.smach.user_data import *  # noqa: F401,F403
