"""minros: a pure-Python ROS 1 middleware. This module is the rospy-compatible public API.

``import rospy`` gives exactly these names (the ``rospy`` stand-in package re-exports them),
so unmodified rospy scripts run on minros. The behaviour lives in the layers below: the node
runtime ``minros.node`` (names, lifecycle) and the client library ``minros.client`` (``init``,
``topics``, ``services``, ``params``, ``rostime``, ``log``, ``msproxy``); this file only maps the
public names to them.

Names are imported on first use (PEP 562), so ``import minros.wire.tcpros`` or a command-line tool
does not pay for the whole client library, and one layer can be used without the others.
Importing this package changes nothing else: the message import hook (``<pkg>.msg`` of any
package on ROS_PACKAGE_PATH) and the ``cv2.imshow`` hook are installed by ``import rospy`` and
``init_node``, where a user program needs them, not in the master or the tools.
"""

from __future__ import annotations

import importlib
import os
from typing import Any, Dict

__version__ = "0.1.0"

_EXCEPTIONS = ("ROSException", "ROSSerializationException", "ROSInitException",
               "ROSInterruptException", "ROSTimeMovedBackwardsException", "ROSInternalException",
               "TransportException", "TransportTerminated", "TransportInitError",
               "ServiceException")
_LOG = ("DEBUG", "INFO", "WARN", "ERROR", "FATAL", "logout",
        *(f"log{level}{suffix}" for level in ("debug", "info", "warn", "err", "fatal")
          for suffix in ("", "_throttle", "_throttle_identical", "_once")))
_NODE = ("spin", "myargv", "on_shutdown", "is_shutdown", "signal_shutdown", "get_node_uri",
         "get_name", "get_caller_id", "get_namespace", "resolve_name", "remap_name")
_INIT = ("init_node",)
_MSPROXY = ("get_master", "MasterProxy")
_PARAMS = ("get_param", "get_param_cached", "get_param_names", "set_param", "delete_param",
           "has_param", "search_param")
_ROSTIME = ("Time", "Duration", "get_rostime", "get_time", "sleep", "Rate", "Timer", "TimerEvent")
_SERVICES = ("Service", "ServiceProxy", "wait_for_service", "parse_rosrpc_uri")
_TOPICS = ("Publisher", "Subscriber", "SubscribeListener", "AnyMsg", "wait_for_message",
           "get_published_topics")

#: public name -> module that defines it
_WHERE: Dict[str, str] = {}
for _module, _names in (("minros.exceptions", _EXCEPTIONS), ("minros.client.log", _LOG),
                        ("minros.node", _NODE), ("minros.client.init", _INIT),
                        ("minros.client.msproxy", _MSPROXY), ("minros.client.params", _PARAMS),
                        ("minros.client.rostime", _ROSTIME), ("minros.client.services", _SERVICES),
                        ("minros.client.topics", _TOPICS)):
    for _name in _names:
        _WHERE[_name] = _module
_WHERE["logerror"] = "minros.client.log"

__all__ = ["Header", "Message", "get_ros_root", *_WHERE]


def get_ros_root(required: bool = False, env: dict | None = None) -> str | None:
    """``ROS_ROOT`` from the environment (None when unset, unless ``required``)."""
    env = os.environ if env is None else env
    root = env.get("ROS_ROOT")
    if required and not root:
        from minros.exceptions import ROSException

        raise ROSException("ROS_ROOT is not set")
    return root


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is not None:
        value = getattr(importlib.import_module(module), name if name != "logerror" else "logerr")
    elif name == "Header":
        from std_msgs.msg import Header as value
    elif name == "Message":
        from minros.msgs import Message as value
    else:
        raise AttributeError(f"module 'minros' has no attribute {name!r}")
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list:
    return sorted(set(globals()) | set(__all__))
