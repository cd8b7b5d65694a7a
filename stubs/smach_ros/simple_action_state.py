"""smach_ros.simple_action_state stand-in (see minros.smach_ros.simple_action_state)."""

from minros.smach_ros.simple_action_state import *  # noqa: F401,F403
