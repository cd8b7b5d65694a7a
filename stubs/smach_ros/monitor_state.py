"""smach_ros.monitor_state stand-in (see minros.smach_ros.monitor_state)."""

from minros.smach_ros.monitor_state import *  # noqa: F401,F403
