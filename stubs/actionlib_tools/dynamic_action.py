"""actionlib_tools.dynamic_action stand-in."""

from minros.actionlib_tools.dynamic_action import *  # noqa: F401,F403
