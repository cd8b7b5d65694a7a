"""rosgraph.impl.graph: the ROS graph polled from the master and the nodes (minros.tools.graph)."""

from minros.tools.graph import (  # noqa: F401
    BadNode,
    Edge,
    EdgeList,
    Graph,
    edge_args,
    node_topic,
    topic_node,
)
