"""genmsg.srvs: SrvSpec (minros.msgs.loader)."""

from genmsg.names import (  # noqa: E402, F401
    is_legal_resource_base_name,
    is_legal_resource_name,
    package_resource_name,
    resource_name,
)
from minros.msgs.loader import SrvSpec  # noqa: F401
