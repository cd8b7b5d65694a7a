"""rospy.impl.paramserver: the node's cache of subscribed parameters (minros.client.params)."""

from __future__ import annotations

from minros.client import params as _params
from minros.client.params import ParamCache as ParamServerCache  # noqa: F401


def get_param_server_cache() -> ParamServerCache:
    """The cache get_param_cached reads and paramUpdate calls fill."""
    return _params._cache
