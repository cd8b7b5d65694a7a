"""rosgraph.names: graph resource names (minros.names)."""

from minros.names import (  # noqa: F401
    ANYTYPE,
    GLOBALNS,
    PRIV_NAME,
    REMAP,
    SEP,
    anonymous_name,
    canonicalize_name,
    get_ros_namespace,
    is_global,
    is_legal_base_name,
    is_legal_name,
    is_legal_remap,
    is_private,
    load_mappings,
    make_caller_id,
    make_global_ns,
    namespace,
    ns_join,
    resolve_name,
    script_resolve_name,
)

MSG_EXT = ".msg"
SRV_EXT = ".srv"


ROS_NAMESPACE = "ROS_NAMESPACE"
