"""roslaunch.server: the XML-RPC servers of parent and child roslaunches
(minros.launch.rosserver)."""

from minros.launch.procmon import Process, ProcessListener  # noqa: F401
from minros.launch.rosrunner import ROSLaunchRunner  # noqa: F401
from minros.launch.rosserver import (  # noqa: F401
    _STARTUP_TIMEOUT,
    DEFAULT_TIMEOUT_SIGINT,
    DEFAULT_TIMEOUT_SIGTERM,
    ChildROSLaunchProcess,
    ROSLaunchBaseHandler,
    ROSLaunchChildHandler,
    ROSLaunchChildNode,
    ROSLaunchNode,
    ROSLaunchParentHandler,
    ROSLaunchParentNode,
    _ProcessListenerForwarder,
)
from roslaunch.core import (  # noqa: E402, F401
    RLException,
    add_printerrlog_handler,
    add_printlog_handler,
    printerrlog,
    printlog,
    printlog_bold,
)

from . import config, launch, pmon, xmlloader  # noqa: F401 - roslaunch.server imports them
