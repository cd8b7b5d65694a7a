"""roslib.names: graph and package resource names (minros.names)."""

from minros.names import (  # noqa: F401
    ANYTYPE,
    GLOBALNS,
    PRIV_NAME,
    PRN_SEPARATOR,
    REMAP,
    SEP,
    anonymous_name,
    canonicalize_name,
    get_ros_namespace,
    is_global,
    is_legal_base_name,
    is_legal_name,
    is_legal_resource_base_name,
    is_legal_resource_name,
    is_private,
    load_mappings,
    make_caller_id,
    make_global_ns,
    namespace,
    ns_join,
    package_resource_name,
    resolve_name,
    resource_name,
    resource_name_base,
    resource_name_package,
)

TYPE_SEPARATOR = PRN_SEPARATOR
