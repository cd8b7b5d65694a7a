"""roslaunch.remote: nodes on other machines (minros.launch.rosserver: minros launches on
this machine only)."""

from minros.launch.rosserver import (  # noqa: F401
    _CHILD_REGISTER_TIMEOUT,
    DEFAULT_TIMEOUT_SIGINT,
    DEFAULT_TIMEOUT_SIGTERM,
    ROSRemoteRunner,
    SSHChildROSLaunchProcess,
)
from roslaunch.core import RLException, is_machine_local, printerrlog, printlog  # noqa: E402, F401

from . import launch  # noqa: F401 - roslaunch.remote imports it
