"""smach_ros.introspection stand-in (see minros.smach_ros.introspection)."""

from minros.smach_ros.introspection import *  # noqa: F401,F403
