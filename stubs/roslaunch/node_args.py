"""roslaunch.node_args: a node's command line and the names of a launch's nodes
(minros.launch.rostools)."""

from minros.launch.rostools import (  # noqa: F401
    NodeParamsException,
    _resolved_name,
    create_local_process_args,
    get_node_args,
    get_node_list,
    print_node_args,
    print_node_filename,
    print_node_list,
)
from rosgraph.names import script_resolve_name  # noqa: E402, F401
from roslaunch.config import load_config_default  # noqa: E402, F401
from roslaunch.core import RLException, local_machine, setup_env  # noqa: E402, F401
