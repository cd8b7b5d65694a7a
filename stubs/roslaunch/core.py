"""roslaunch.core: roslaunch's data model (minros.launch.rosmodel, minros.launch.api)."""

from rospkg.environment import get_ros_package_path, get_ros_root  # noqa: E402, F401

from minros.launch.api import Node  # noqa: F401
from minros.launch.rosmodel import (  # noqa: F401
    PHASE_RUN,
    PHASE_SETUP,
    PHASE_TEARDOWN,
    TEST_TIME_LIMIT_DEFAULT,
    Executable,
    Machine,
    Master,
    Param,
    RLException,
    RosbinExecutable,
    Test,
    _xml_escape,
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
