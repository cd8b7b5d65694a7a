"""roslaunch.nodeprocess: local processes for the process monitor (minros.launch.nodeproc)."""

from rospkg.environment import get_ros_package_path, get_ros_root  # noqa: E402, F401

from minros.launch.nodeproc import (  # noqa: F401
    DEFAULT_TIMEOUT_SIGINT,
    DEFAULT_TIMEOUT_SIGTERM,
    NUM_WORKERS,
    LocalProcess,
    _cleanup_remappings,
    _next_counter,
    create_master_process,
    create_node_process,
)
from roslaunch.core import (  # noqa: E402, F401
    Executable,
    Machine,
    Master,
    Node,
    Param,
    RLException,
    RosbinExecutable,
    Test,
    add_printerrlog_handler,
    add_printlog_handler,
    clear_printerrlog_handlers,
    clear_printlog_handlers,
    generate_run_id,
    is_child_mode,
    is_machine_local,
    local_machine,
    printerrlog,
    printlog,
    printlog_bold,
    remap_localhost_uri,
    rle_wrapper,
    set_child_mode,
    setup_env,
)
from roslaunch.node_args import create_local_process_args  # noqa: E402, F401
from roslaunch.pmon import FatalProcessLaunch, Process  # noqa: E402, F401

PHASE_RUN = "run"
PHASE_SETUP = "setup"
PHASE_TEARDOWN = "teardown"
TEST_TIME_LIMIT_DEFAULT = 60
