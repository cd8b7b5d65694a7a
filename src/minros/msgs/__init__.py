"""minros's ROS 1 message system: parse .msg/.srv, md5 sums, full texts, generated classes.

    from minros.msgs import get_message_class
    String = get_message_class("std_msgs/String")
    buf = io.BytesIO(); String("hi").serialize(buf)

Message classes honour genpy's contract (``__slots__``, ``_type``, ``_md5sum``, ``_full_text``,
``_has_header``, ``_slot_types``, constructors, ``serialize``/``deserialize``, YAML ``str()``)
and produce genpy's bytes. Importing this package installs the import hook that makes
``<pkg>.msg``/``<pkg>.srv`` of any package on ROS_PACKAGE_PATH importable without a build.
"""

from __future__ import annotations

from minros.exceptions import DeserializationError, SerializationError

from .importer import install_import_hook, write_stub_package
from .message import Message, check_type, strify_message
from .registry import (
    REGISTRY,
    MsgContext,
    ServiceDefinition,
    UnknownTypeError,
    generate_dynamic,
    get_message_class,
    get_service_class,
    normalize_type,
    numpy_msg,
)
from .spec import MsgSpecError
from .tval import Duration, Time, TVal

__all__ = [
    "Message", "Time", "Duration", "TVal", "get_message_class", "get_service_class",
    "generate_dynamic", "numpy_msg", "UnknownTypeError", "MsgSpecError", "MsgContext",
    "REGISTRY", "ServiceDefinition", "install_import_hook", "write_stub_package",
    "check_type", "strify_message", "normalize_type", "DeserializationError",
    "SerializationError",
]

install_import_hook()
