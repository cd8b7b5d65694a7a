"""rosunit.pmon: the process monitor rosunit runs test processes under; minros has one, the
launcher's (minros.launch.procmon, also roslaunch.pmon). Its errors (a duplicate process name,
a monitor already shut down) are RLExceptions, so PmonException names that class."""

from minros.launch.procmon import (  # noqa: F401
    DeadProcess,
    FatalProcessLaunch,
    Process,
    ProcessListener,
    ProcessMonitor,
    pmon_shutdown,
    printerrlog,
    printlog,
    printlog_bold,
    shutdown_process_monitor,
    start_process_monitor,
)
from minros.launch.rosmodel import RLException as PmonException  # noqa: F401
