"""roslaunch.parent: ROSLaunchParent (minros.launch.api)."""

from minros.launch.api import ROSLaunchParent  # noqa: F401
