"""roslaunch.remoteprocess: child roslaunches over SSH (minros.launch.rosserver: minros
launches on this machine only; the known_hosts check is real, starting a child says why not)."""

from minros.launch.rosserver import (  # noqa: F401
    DEFAULT_TIMEOUT_SIGINT,
    DEFAULT_TIMEOUT_SIGTERM,
    TIMEOUT_SSH_CONNECT,
    SSHChildROSLaunchProcess,
    ssh_check_known_hosts,
)
from roslaunch.core import printerrlog, printlog  # noqa: E402, F401

from . import pmon, server  # noqa: F401 - roslaunch.remoteprocess imports them
