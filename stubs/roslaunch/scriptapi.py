"""roslaunch.scriptapi: ROSLaunch (minros.launch.api)."""

from minros.launch.api import ROSLaunch  # noqa: F401
