"""smach_ros.service_state stand-in (see minros.smach_ros.service_state)."""

from minros.smach_ros.service_state import *  # noqa: F401,F403
