"""rospy.client: node life-cycle functions (minros.node and minros.client.topics)."""

from minros.client.topics import get_published_topics, wait_for_message  # noqa: F401
from minros.node import (  # noqa: F401
    get_master,
    init_node,
    myargv,
    on_shutdown,
    spin,
)
