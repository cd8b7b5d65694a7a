"""rospy.names: the node's names and remappings (minros.node) and rosgraph name helpers."""

from minros.names import (  # noqa: F401
    ANYTYPE,
    SEP,
    SERVICE_ANYTYPE,
    TOPIC_ANYTYPE,
    canonicalize_name,
    is_global,
    is_private,
    namespace,
    ns_join,
    scoped_name,
)
from minros.node import (  # noqa: F401
    get_caller_id,
    get_mappings,
    get_name,
    get_namespace,
    remap_name,
    resolve_name,
)
