"""rosgraph.xmlrpc: XML-RPC servers bound and named by ROS's rules (minros.wire.xmlrpc_node)."""

from minros.wire.xmlrpc_node import (  # noqa: F401
    ThreadingXMLRPCServer,
    XmlRpcHandler,
    XmlRpcNode,
)


def isstring(s: object) -> bool:
    return isinstance(s, str)
