"""roslib.scriptutil: deprecated helpers of old ROS scripts (name resolution without
remappings, an XML-RPC handle on the master), over minros.names."""

from __future__ import annotations

import functools
import os
import warnings
import xmlrpc.client
from typing import Any, Callable

from minros import names

_GLOBAL_CALLER_ID = "/script"


def deprecated(func: Callable) -> Callable:
    """Mark ``func`` deprecated: each call warns (DeprecationWarning)."""
    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        warnings.warn(f"Call to deprecated function {func.__name__}.",
                      category=DeprecationWarning, stacklevel=2)
        return func(*args, **kwargs)
    return wrapper


@deprecated
def script_resolve_name(script_name: str, name: str) -> str:
    """``name`` resolved for a script: ROS_NAMESPACE applies, ``~`` is the script's own
    namespace; no remappings."""
    if not name:
        return names.get_ros_namespace()
    if names.is_global(name):
        return name
    if names.is_private(name):
        return names.ns_join(names.make_caller_id(script_name), name[1:])
    return names.get_ros_namespace() + name


@deprecated
def get_master() -> xmlrpc.client.ServerProxy:
    """An XML-RPC proxy on ROS_MASTER_URI (KeyError when it is unset); rosgraph.Master is
    the better API."""
    return xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])


@deprecated
def get_param_server() -> xmlrpc.client.ServerProxy:
    return get_master.__wrapped__()
