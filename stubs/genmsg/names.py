"""genmsg.names: package resource names (minros.names)."""

from minros.names import (  # noqa: F401
    PRN_SEPARATOR,
    is_legal_resource_base_name,
    is_legal_resource_name,
    normalize_package_context,
    package_resource_name,
    resource_name,
    resource_name_base,
    resource_name_package,
)
