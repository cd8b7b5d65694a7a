"""The dynamic_reconfigure server a node runs to have its parameters tuned while it runs.

Under its namespace (the node's private one, ``~``, by default) it serves
``set_parameters`` (``dynamic_reconfigure/Reconfigure``) and publishes, latched,
``parameter_descriptions`` (``ConfigDescription``, once) and ``parameter_updates`` (``Config``,
after each change). Values start from the type's defaults, overridden by the parameter server,
clamped to [min, max]; every change goes through the user's callback
``callback(config, level) -> config`` and is written back to the parameter server.
"""

from __future__ import annotations

import copy
import threading
from typing import Any, Callable, Dict

import minros
from dynamic_reconfigure.msg import Config as ConfigMsg
from dynamic_reconfigure.msg import ConfigDescription as ConfigDescrMsg
from dynamic_reconfigure.srv import Reconfigure as ReconfigureSrv

from . import DynamicReconfigureCallbackException
from .encoding import (
    decode_config,
    encode_config,
    encode_description,
    extract_params,
    get_tree,
    initial_config,
)


def namespace_of(namespace: str) -> str:
    """Where a server's topics, service and parameters live: ``~`` or ``<ns>/``."""
    if not namespace:
        return "~"
    if namespace[0] not in "/~":
        namespace = "~" + namespace
    return (namespace + "/").replace("//", "/")


def calc_level(description: Dict[str, Any], new: Dict[str, Any], old: Dict[str, Any]) -> int:
    """The OR of the levels of the parameters whose values differ."""
    level = 0
    for param in extract_params(description):
        if new[param["name"]] != old[param["name"]]:
            level |= param["level"]
    return level


def clamp(config_type: Any, config: Dict[str, Any]) -> None:
    """Bring each value of ``config`` within its parameter's [min, max] (strings excepted)."""
    for param in extract_params(config_type.config_description):
        name = param["name"]
        high, low, value = config_type.max[name], config_type.min[name], config[name]
        if value > high and high != "":
            config[name] = high
        elif value < low and low != "":
            config[name] = low


class Server:
    """Serve the configuration type ``type`` (a generated ``<Name>Config`` module)."""

    def __init__(self, type: Any, callback: Callable[[Any, int], Any], namespace: str = "") -> None:
        self.mutex = threading.Lock()
        self.ns = namespace_of(namespace)
        self.type = type
        self.config = type.defaults.copy()
        self.description = encode_description(type)
        self._copy_from_parameter_server()
        self.callback = callback
        self._clamp(self.config)
        self.config["groups"] = get_tree(self.description)
        self.config = initial_config(encode_config(self.config), type.config_description)
        self.descr_topic = minros.Publisher(self.ns + "parameter_descriptions", ConfigDescrMsg,
                                            latch=True, queue_size=10)
        self.descr_topic.publish(self.description)
        self.update_topic = minros.Publisher(self.ns + "parameter_updates", ConfigMsg, latch=True,
                                             queue_size=10)
        # the first call gets level ~0 (all bits), as in the C++ server
        self._change_config(self.config, ~0)
        self.set_service = minros.Service(self.ns + "set_parameters", ReconfigureSrv,
                                          self._set_callback)

    def update_configuration(self, changes: Dict[str, Any]) -> Any:
        """Apply ``changes`` (name -> value) through the callback; returns the new config."""
        with self.mutex:
            new_config = copy.deepcopy(self.config)
            new_config.update(changes)
            self._clamp(new_config)
            return self._change_config(new_config, self._calc_level(new_config, self.config))

    def _copy_from_parameter_server(self) -> None:
        for param in extract_params(self.type.config_description):
            try:
                self.config[param["name"]] = minros.get_param(self.ns + param["name"])
            except KeyError:
                pass

    def _copy_to_parameter_server(self) -> None:
        for param in extract_params(self.type.config_description):
            minros.set_param(self.ns + param["name"], self.config[param["name"]])

    def _change_config(self, config: Any, level: int) -> Any:
        self.config = self.callback(config, level)
        if self.config is None:
            text = "Reconfigure callback should return a possibly updated configuration."
            minros.logerr(text)
            raise DynamicReconfigureCallbackException(text)
        self._copy_to_parameter_server()
        self.update_topic.publish(encode_config(self.config))
        return self.config

    def _calc_level(self, config1: Dict[str, Any], config2: Dict[str, Any]) -> int:
        return calc_level(self.type.config_description, config1, config2)

    def _clamp(self, config: Dict[str, Any]) -> None:
        clamp(self.type, config)

    def _set_callback(self, req: Any) -> Any:
        changes = decode_config(req.config, self.type.config_description)
        return encode_config(self.update_configuration(changes))
