"""roslaunch.nodeprocess: local processes for the process monitor (minros.launch.nodeproc)."""

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
