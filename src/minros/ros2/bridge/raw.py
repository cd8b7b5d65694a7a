"""ROS 1 message and service classes that carry serialized bytes under a type, pure.

The bridge never builds ROS 1 message objects: a subscriber with one of these classes keeps
each message's TCPROS bytes (``_buff``) and the connection header; a publisher sends
``_buff`` as it is, telling subscribers the type, md5sum and definition the class names.
``_keeps_buffer = False``: a message's bytes are converted before its callback returns, so a
subscriber receives the next big frame into the same buffer.
"""

from __future__ import annotations

import threading
from typing import Any, Dict, List, Tuple

__all__ = ["RawMessage", "raw_class", "raw_service_class"]


class RawMessage:
    """Bytes under a ROS 1 type (subclasses name it)."""

    __slots__ = ("_buff", "_connection_header")
    _type = "*"
    _md5sum = "*"
    _full_text = ""
    _has_header = False
    _keeps_buffer = False
    _slot_types: List[str] = []

    def __init__(self, buff: Any = None) -> None:
        self._buff = buff

    def serialize(self, buff: Any) -> None:
        buff.write(self._buff)

    def deserialize(self, data: Any) -> RawMessage:
        self._buff = data
        return self


_classes: Dict[Tuple[str, str, str], type] = {}
_services: Dict[Tuple[str, str], type] = {}
_lock = threading.Lock()


def raw_class(type_name: str, md5sum: str = "*", definition: str = "") -> type:
    """The raw class of (type, md5sum, definition), made once. md5sum ``*`` subscribes to any
    publisher of the topic (its connection header then says what it sends)."""
    key = (type_name, md5sum, definition)
    with _lock:
        cls = _classes.get(key)
        if cls is None:
            cls = type("Raw_" + type_name.replace("/", "_"), (RawMessage,),
                       {"__slots__": (), "_type": type_name, "_md5sum": md5sum,
                        "_full_text": definition})
            _classes[key] = cls
        return cls


def raw_service_class(type_name: str, md5sum: str) -> type:
    """A ROS 1 service class whose requests and responses are raw bytes."""
    key = (type_name, md5sum)
    with _lock:
        cls = _services.get(key)
        if cls is not None:
            return cls
    request = raw_class(type_name + "Request", md5sum)
    response = raw_class(type_name + "Response", md5sum)
    with _lock:
        cls = _services.setdefault(key, type(
            "RawService_" + type_name.replace("/", "_"), (),
            {"_type": type_name, "_md5sum": md5sum, "_request_class": request,
             "_response_class": response}))
        return cls
