"""smach_ros.util stand-in (see minros.smach_ros.util)."""

from minros.smach_ros.util import *  # noqa: F401,F403
