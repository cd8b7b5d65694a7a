"""smach_ros.action_server_wrapper stand-in (see minros.smach_ros.action_server_wrapper)."""

from minros.smach_ros.action_server_wrapper import *  # noqa: F401,F403
