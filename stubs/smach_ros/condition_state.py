"""smach_ros.condition_state stand-in (see minros.smach_ros.condition_state)."""

from minros.smach_ros.condition_state import *  # noqa: F401,F403
