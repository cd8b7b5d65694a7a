"""roslaunch.parent: ROSLaunchParent, a roslaunch run from Python (minros.launch.rosserver:
process monitor, XML-RPC server, ROSLaunchRunner)."""

from minros.launch.nodeproc import NUM_WORKERS  # noqa: F401
from minros.launch.rosmodel import load_config_default  # noqa: F401
from minros.launch.rosserver import (  # noqa: F401
    DEFAULT_TIMEOUT_SIGINT,
    DEFAULT_TIMEOUT_SIGTERM,
    ROSLaunchParent,
)
from roslaunch.core import RLException, printerrlog, printlog_bold  # noqa: E402, F401

from . import config, launch, pmon, server  # noqa: F401 - roslaunch.parent imports them
