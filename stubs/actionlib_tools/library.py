"""actionlib_tools.library stand-in."""

from minros.actionlib_tools.library import *  # noqa: F401,F403
