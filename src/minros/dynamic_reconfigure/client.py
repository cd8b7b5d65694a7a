"""The dynamic_reconfigure client: read and change another node's configuration."""

from __future__ import annotations

import sys
import threading
import time
from typing import Any, Callable, Dict, List

import minros
from dynamic_reconfigure.msg import Config as ConfigMsg
from dynamic_reconfigure.msg import ConfigDescription as ConfigDescrMsg
from dynamic_reconfigure.srv import Reconfigure as ReconfigureSrv

from . import DynamicReconfigureCallbackException, DynamicReconfigureParameterException
from .encoding import decode_config, decode_description, encode_config, extract_params

_TYPES = {"int": int, "double": float, "str": str, "bool": bool}


def param_type_from_string(type_str: str) -> type:
    """The Python type of a parameter type name ('int', 'double', 'str', 'bool')."""
    try:
        return _TYPES[type_str]
    except KeyError:
        raise DynamicReconfigureParameterException(
            f"parameter has unknown type: {type_str}. This is a bug in dynamic_reconfigure.") from None


def convert_value(name: str, value: Any, dest_type: type, edit_method: str) -> Any:
    """``value`` as the parameter's type, the way ROS's client converts what users give it:
    "true"/"yes"/"t"/"1" for bools, an enum constant's name for enum parameters, else the
    type's constructor. Raises :class:`DynamicReconfigureParameterException` if it cannot."""
    try:
        if dest_type is bool and type(value) is str:
            return value.lower() in ("yes", "true", "t", "1")
        if type(value) is str and edit_method != "":
            for const in _enum_constants(edit_method):
                if value.lower() == const["name"].lower():
                    return param_type_from_string(const["type"])(const["value"])
        return dest_type(value)
    except ValueError as exc:
        raise DynamicReconfigureParameterException(
            f"can't set parameter '{name}' of {dest_type}: {exc}") from None


def _enum_constants(edit_method: str) -> List[Dict[str, Any]]:
    """The constants of an enum ``edit_method`` (the repr of a dict; parsed, never evaluated)."""
    import ast

    try:
        described = ast.literal_eval(edit_method)
        return list(described["enum"])
    except (ValueError, SyntaxError, KeyError, TypeError, MemoryError, RecursionError):
        return []


class Client:
    """Connects to the dynamic_reconfigure server ``name`` (usually a node name)."""

    def __init__(self, name: str, timeout: float | None = None,
                 config_callback: Callable | None = None,
                 description_callback: Callable | None = None) -> None:
        self.name = name
        self.config: Any = None
        self.param_description: Any = None
        self.group_description: Any = None
        self._param_types: Dict[str, type] | None = None
        self._cv = threading.Condition()
        self._config_callback = config_callback
        self._description_callback = description_callback
        self._set_service = self._get_service_proxy("set_parameters", timeout)
        self._descriptions_sub = self._get_subscriber("parameter_descriptions", ConfigDescrMsg,
                                                      self._descriptions_msg)
        self._updates_sub = self._get_subscriber("parameter_updates", ConfigMsg, self._updates_msg)

    def _wait_for(self, attribute: str, timeout: float | None) -> Any:
        """Wait until ``self.<attribute>`` is set (forever for None/0); its value or None."""
        deadline = None if not timeout else time.monotonic() + timeout
        with self._cv:
            while getattr(self, attribute) is None:
                if minros.is_shutdown():
                    return None
                if deadline is None:
                    self._cv.wait(1.0)  # notified on arrival; the timeout notices shutdown
                    continue
                left = deadline - time.monotonic()
                if left <= 0.0:
                    break
                self._cv.wait(left)
        return getattr(self, attribute)

    def get_configuration(self, timeout: float | None = None) -> Any:
        """The server's latest configuration (waiting for one); None on timeout."""
        if not timeout:
            if self._wait_for("config", 1.0) is None:
                print("Waiting for configuration...", file=sys.stderr)
                return self._wait_for("config", None)
            return self.config
        return self._wait_for("config", timeout)

    def get_parameter_descriptions(self, timeout: float | None = None) -> Any:
        return self._wait_for("param_description", timeout)

    def get_group_descriptions(self, timeout: float | None = None) -> Any:
        return self._wait_for("group_description", timeout)

    def update_configuration(self, changes: Dict[str, Any]) -> Any:
        """Send ``changes`` (name -> value, values converted to the parameters' types);
        returns the configuration the server ended up with."""
        if self.param_description is None:
            self.get_parameter_descriptions()
        if self.param_description is not None:
            for name, value in list(changes.items()):
                if name == "groups":
                    continue
                dest_type = self._param_types.get(name) if self._param_types else None
                if dest_type is None:
                    raise DynamicReconfigureParameterException(f"don't know parameter: {name}")
                descr = [p for p in self.param_description if p["name"].lower() == name.lower()][0]
                changes[name] = convert_value(name, value, dest_type, descr["edit_method"])
        if "groups" in changes:
            changes["groups"] = self.update_groups(changes["groups"])
        config = encode_config(changes)
        try:
            msg = self._set_service(config).config
        except minros.ServiceException:
            raise DynamicReconfigureCallbackException("service call failed") from None
        if self.group_description is None:
            self.get_group_descriptions()
        return decode_config(msg, self.group_description)

    def update_groups(self, changes: Dict[str, Any]) -> Any:
        """The group tree with the states of the groups named in ``changes`` replaced."""
        descr = self.get_group_descriptions()

        def update_state(group: str, description: Dict[str, Any]) -> Dict[str, Any]:
            for key, sub in description["groups"].items():
                if sub["name"] == group:
                    description["groups"][key]["state"] = changes[group]
                else:
                    update_state(group, sub)
            return description

        for change in changes:
            descr = update_state(change, descr)
        return descr

    def close(self) -> None:
        self._descriptions_sub.unregister()
        self._updates_sub.unregister()

    def get_config_callback(self) -> Callable | None:
        return self._config_callback

    def set_config_callback(self, value: Callable | None) -> None:
        self._config_callback = value
        if value is not None:
            value(self.config)

    config_callback = property(get_config_callback, set_config_callback)

    def get_description_callback(self) -> Callable | None:
        return self._description_callback

    def set_description_callback(self, value: Callable | None) -> None:
        self._description_callback = value
        if value is not None:
            value(self.param_description)

    description_callback = property(get_description_callback, set_description_callback)

    def _get_service_proxy(self, suffix: str, timeout: float | None) -> Any:
        service_name = minros.resolve_name(self.name + "/" + suffix)
        if not timeout:
            try:
                minros.wait_for_service(service_name, 1.0)
            except minros.ROSException:
                print(f"Waiting for service {service_name}...", file=sys.stderr)
                minros.wait_for_service(service_name, timeout)
        else:
            minros.wait_for_service(service_name, timeout)
        return minros.ServiceProxy(service_name, ReconfigureSrv)

    def _get_subscriber(self, suffix: str, msg_type: type, callback: Callable) -> Any:
        return minros.Subscriber(minros.resolve_name(self.name + "/" + suffix), msg_type,
                                 callback=callback)

    def _updates_msg(self, msg: Any) -> None:
        if self.group_description is None:
            self.get_group_descriptions()
        self.config = decode_config(msg, self.group_description)
        with self._cv:
            self._cv.notify_all()
        if self._config_callback is not None:
            self._config_callback(self.config)

    def _descriptions_msg(self, msg: Any) -> None:
        self.group_description = decode_description(msg)
        self.param_description = extract_params(self.group_description)
        self._param_types = {}
        for param in self.param_description:
            name, kind = param.get("name"), param.get("type")
            if name is not None and kind is not None:
                self._param_types[name] = param_type_from_string(kind)
        with self._cv:
            self._cv.notify_all()
        if self._description_callback is not None:
            self._description_callback(self.param_description)

    def _param_type_from_string(self, type_str: str) -> type:
        return param_type_from_string(type_str)
