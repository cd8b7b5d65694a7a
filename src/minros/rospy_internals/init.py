"""rospy.impl.init: the node's XML-RPC server start (minros.node) and its console handler."""

from __future__ import annotations

from typing import Any, Mapping, Optional

from minros import node as _node
from minros import roslogging
from minros.names import SEP, namespace

DEFAULT_NODE_PORT = 0
DEFAULT_MASTER_PORT = 11311
DEFAULT_MASTER_URI = _node.DEFAULT_MASTER_URI


def start_node(environ: Mapping[str, str], resolved_name: str, master_uri: Optional[str] = None,
               port: int = 0, tcpros_port: int = 0) -> Any:
    """Name the process's node ``resolved_name`` and start its servers; the node."""
    me = _node.default_node()
    argv = [f"__ns:={namespace(resolved_name)}"]
    if master_uri:
        argv.append(f"__master:={master_uri}")
    me.init(resolved_name.rsplit(SEP, 1)[-1], argv, xmlrpc_port=port, tcpros_port=tcpros_port)
    return me


class RosStreamHandler(roslogging.RosStreamHandler):
    """rospy's console handler (rosgraph.roslogging's)."""
