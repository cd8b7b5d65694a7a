"""roslaunch.child: a child roslaunch serving its parent (minros.launch.rosserver)."""

from minros.launch.rosserver import (  # noqa: F401
    DEFAULT_TIMEOUT_SIGINT,
    DEFAULT_TIMEOUT_SIGTERM,
    ROSLaunchChild,
)

from . import pmon, server  # noqa: F401 - roslaunch.child imports them
