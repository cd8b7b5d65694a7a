"""rospy.core: shutdown state, node URI and logging functions (minros.node, minros.client.log)."""

from minros.client.log import logdebug, logerr, logfatal, loginfo, logwarn  # noqa: F401
from minros.node import (  # noqa: F401
    add_shutdown_hook,
    get_node_uri,
    is_initialized,
    is_shutdown,
    is_shutdown_requested,
    signal_shutdown,
)
