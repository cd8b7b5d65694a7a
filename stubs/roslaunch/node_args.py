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
