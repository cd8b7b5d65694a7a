"""minros's ROS 1 message system: parse .msg/.srv, md5 sums, full texts, generated classes.

    from minros.msgs import get_message_class
    String = get_message_class("std_msgs/String")
    buf = io.BytesIO(); String("hi").serialize(buf)

Message classes honour genpy's contract (``__slots__``, ``_type``, ``_md5sum``, ``_full_text``,
``_has_header``, ``_slot_types``, constructors, ``serialize``/``deserialize``, YAML ``str()``)
and produce genpy's bytes. :func:`install_import_hook` makes ``<pkg>.msg``/``<pkg>.srv`` of any
package on ROS_PACKAGE_PATH importable without a build; ``import rospy`` and ``init_node`` call
it (importing this package does not).
"""

from __future__ import annotations

from typing import Any

from minros.exceptions import DeserializationError, SerializationError

from .importer import install_import_hook, write_stub_package
from .tval import Duration, Time, TVal

#: name -> submodule; loaded on first use so ``import rospy`` stays light (PEP 562)
_LAZY = {
    "Message": "message", "check_type": "message", "strify_message": "message",
    "reader_for": "message",
    "REGISTRY": "registry", "MsgContext": "registry", "ServiceDefinition": "registry",
    "UnknownTypeError": "registry", "generate_dynamic": "registry",
    "get_message_class": "registry", "get_service_class": "registry",
    "normalize_type": "registry", "numpy_msg": "registry", "MsgSpecError": "spec",
}

__all__ = [
    "Message", "Time", "Duration", "TVal", "get_message_class", "get_service_class",
    "generate_dynamic", "numpy_msg", "UnknownTypeError", "MsgSpecError", "MsgContext",
    "REGISTRY", "ServiceDefinition", "install_import_hook", "write_stub_package",
    "check_type", "strify_message", "normalize_type", "DeserializationError",
    "SerializationError", "reader_for",
]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'minros.msgs' has no attribute '{name}'")
    import importlib

    value = getattr(importlib.import_module(f"minros.msgs.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list:
    return sorted(set(globals()) | set(__all__))
