"""Stand-in for rosnode's Python API (minros.cli.node: the code the command runs)."""

from minros.cli.node import (  # noqa: F401
    ID,
    NAME,
    ROSNodeException,
    ROSNodeIOException,
    cleanup_master_blacklist,
    cleanup_master_whitelist,
    get_machines_by_nodes,
    get_node_connection_info_description,
    get_node_info_description,
    get_nodes_by_machine,
    lookup_uri,
    rosnode_cleanup,
    rosnode_listnodes,
    rosnode_ping,
    rosnodemain,
)
from minros.cli.node import rosnode_get_api_uri as get_api_uri  # noqa: F401
from minros.cli.node import rosnode_get_node_names as get_node_names  # noqa: F401
from minros.cli.node import rosnode_info_api as rosnode_info  # noqa: F401
from minros.cli.node import rosnode_kill_nodes as kill_nodes  # noqa: F401
from minros.cli.node import rosnode_ping_all as rosnode_ping_all  # noqa: F401

#: rosnode's old name for rosnode_info
rosnode_debugnode = rosnode_info
