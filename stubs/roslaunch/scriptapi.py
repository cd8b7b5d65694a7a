"""roslaunch.scriptapi: ROSLaunch (minros.launch.api)."""

from minros.launch.api import ROSLaunch  # noqa: F401
from roslaunch.core import Master, Node, RLException  # noqa: E402, F401
