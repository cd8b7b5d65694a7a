"""rospy.impl.paramserver: the node's parameter cache (minros.rospy_internals.paramserver)."""

from minros.names import GLOBALNS, SEP  # noqa: F401
from minros.rospy_internals.paramserver import (  # noqa: F401
    ParamServerCache,
    get_param_server_cache,
)
