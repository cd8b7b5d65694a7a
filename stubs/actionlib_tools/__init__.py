"""actionlib_tools stand-in (see minros.actionlib_tools)."""

from minros.actionlib_tools import *  # noqa: F401,F403
