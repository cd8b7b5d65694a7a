"""Forwarding messages of any type as bytes (ROS's ShapeShifter).

An input subscribes with ``AnyMsg``; the output is advertised when the first message arrives,
under the type, md5 sum and definition its publisher sent in the connection header, and
latched if that publisher latches. Later messages of another type are dropped with one error
line: one topic carries one type.
"""

from __future__ import annotations

import threading
from typing import Any, Callable, Dict, Optional

import minros

__all__ = ["RawMessage", "raw_class", "RawOutput"]


class RawMessage:
    """Bytes sent as they are; subclasses carry a type, md5 sum and definition."""

    __slots__ = ("_buff",)
    _type = ""
    _md5sum = ""
    _full_text = ""
    _has_header = False
    _slot_types: list = []

    def __init__(self, buff: bytes = b"") -> None:
        self._buff = buff

    def serialize(self, buff: Any) -> None:
        buff.write(self._buff)

    def deserialize(self, data: Any) -> RawMessage:
        self._buff = bytes(data)
        return self


_classes: Dict[tuple, type] = {}
_classes_lock = threading.Lock()


def raw_class(type_name: str, md5sum: str, definition: str) -> type:
    """The RawMessage class of one (type, md5, definition), made once."""
    key = (type_name, md5sum, definition)
    with _classes_lock:
        cls = _classes.get(key)
        if cls is None:
            cls = type("RawMessage", (RawMessage,), {
                "__slots__": (), "_type": type_name, "_md5sum": md5sum,
                "_full_text": definition})
            _classes[key] = cls
        return cls


def header_of(msg: Any) -> Dict[str, str]:
    return getattr(msg, "_connection_header", None) or {}


class RawOutput:
    """One output topic, advertised from the first message forwarded to it."""

    def __init__(self, topic: str, queue_size: int = 100,
                 on_advertise: Optional[Callable[[Any], None]] = None,
                 subscriber_listener: Any = None) -> None:
        self.topic = topic
        self.queue_size = queue_size
        self.publisher: Any = None
        self.cls: Optional[type] = None
        self._lock = threading.Lock()
        self._warned = False
        self._on_advertise = on_advertise
        self._listener = subscriber_listener

    @property
    def advertised(self) -> bool:
        return self.publisher is not None

    def advertise(self, msg: Any) -> None:
        """Advertise the output under ``msg``'s type (its first message), if not yet."""
        header = header_of(msg)
        with self._lock:
            if self.publisher is None:
                self.cls = raw_class(header.get("type", "*"), header.get("md5sum", "*"),
                                     header.get("message_definition", ""))
                self.publisher = minros.Publisher(
                    self.topic, self.cls, queue_size=self.queue_size,
                    latch=header.get("latching", "0") == "1",
                    subscriber_listener=self._listener)
                if self._on_advertise is not None:
                    self._on_advertise(self.publisher)

    def forward(self, msg: Any) -> bool:
        """Publish ``msg`` (an AnyMsg received by a subscriber); False if its type differs
        from the one the output was advertised with."""
        header = header_of(msg)
        self.advertise(msg)
        with self._lock:
            if header.get("md5sum") not in (self.cls._md5sum, None):  # type: ignore[union-attr]
                if not self._warned:
                    self._warned = True
                    minros.logerr(f"{self.topic} carries {self.cls._type} "  # type: ignore[union-attr]
                                  f"(md5 {self.cls._md5sum}); dropping messages of type "  # type: ignore[union-attr]
                                  f"{header.get('type')} (md5 {header.get('md5sum')})")
                return False
        self.publisher.publish(self.cls(msg._buff))  # type: ignore[misc]
        return True

    def get_num_connections(self) -> int:
        return self.publisher.get_num_connections() if self.publisher is not None else 0

    def unregister(self) -> None:
        if self.publisher is not None:
            self.publisher.unregister()
