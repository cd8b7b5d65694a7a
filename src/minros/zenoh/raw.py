"""Message and service classes that carry serialized bytes under a foreign type.

The bridge never deserializes: a subscriber with one of these classes registers the real
type and md5sum (so the master lists them and publishers of another md5sum are refused) and
keeps each message's bytes in ``_buff``; a publisher with one sends ``_buff`` as it is and
tells subscribers the definition it was given.

``_keeps_buffer = False``: the bridge is done with a message's bytes when its callback returns
(Zenoh copies what it is given to put), so a subscriber may receive the next big frame into
the same buffer instead of allocating one per image.
"""

from __future__ import annotations

import threading
from typing import Dict, Tuple

import minros

__all__ = ["raw_class", "raw_service_class"]

_classes: Dict[Tuple[str, str, str], type] = {}
_lock = threading.Lock()


def raw_class(type_name: str, md5sum: str, definition: str = "") -> type:
    """The raw message class of (type, md5sum, definition), made once."""
    key = (type_name, md5sum, definition)
    with _lock:
        cls = _classes.get(key)
        if cls is None:
            cls = type("Raw_" + type_name.replace("/", "_"), (minros.AnyMsg,),
                       {"__slots__": (), "_type": type_name, "_md5sum": md5sum,
                        "_full_text": definition, "_has_header": False,
                        "_keeps_buffer": False})
            _classes[key] = cls
        return cls


def raw_service_class(type_name: str, md5sum: str) -> type:
    """A service class whose requests and responses are raw bytes."""
    request = raw_class(type_name + "Request", md5sum)
    response = raw_class(type_name + "Response", md5sum)
    return type("RawService", (), {"_type": type_name, "_md5sum": md5sum,
                                   "_request_class": request, "_response_class": response})
