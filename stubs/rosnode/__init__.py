"""Stand-in for rosnode's Python API (minros.cli.node: the code the command runs)."""

from minros.cli.node import (  # noqa: F401
    ROSNodeException,
    ROSNodeIOException,
    rosnode_info,
    rosnode_ping,
    rosnodemain,
)
from minros.cli.node import rosnode_get_api_uri as get_api_uri  # noqa: F401
from minros.cli.node import rosnode_get_node_names as get_node_names  # noqa: F401
from minros.cli.node import rosnode_kill_nodes as kill_nodes  # noqa: F401
from minros.cli.node import rosnode_ping_all as rosnode_ping_all  # noqa: F401
