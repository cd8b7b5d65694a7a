"""Decode raw messages (``AnyMsg``) with the publisher's own definition.

Tools subscribe with md5 ``*`` and read the publisher's connection header: when the type is
installed with the same md5 sum the installed class is used, otherwise a class is generated
from the header's ``message_definition`` (so types nobody installed still print).
"""

from __future__ import annotations

import threading
from typing import Any, Dict, Tuple


class DecodeError(Exception):
    pass


class Decoder:
    def __init__(self) -> None:
        self._classes: Dict[Tuple[str, str], Any] = {}
        self._lock = threading.Lock()

    def class_for_header(self, header: Dict[str, str]) -> Any:
        type_name = header.get("type", "")
        md5 = header.get("md5sum", "")
        key = (type_name, md5)
        cls = self._classes.get(key)
        if cls is not None:
            return cls
        with self._lock:
            cls = self._classes.get(key)
            if cls is None:
                cls = load_class(type_name, md5, header.get("message_definition", ""))
                self._classes[key] = cls
        return cls

    def decode(self, raw: Any) -> Any:
        header = getattr(raw, "_connection_header", None) or {}
        cls = self.class_for_header(header)
        msg = cls()
        msg.deserialize(raw._buff)
        try:
            msg._connection_header = header
        except AttributeError:
            pass
        return msg


def load_class(type_name: str, md5: str, definition: str) -> Any:
    """Installed class of ``type_name`` if its md5 matches, else one built from ``definition``."""
    from minros.msgs import UnknownTypeError, generate_dynamic, get_message_class

    installed: Any | None = None
    try:
        installed = get_message_class(type_name)
    except (UnknownTypeError, ValueError, LookupError):
        installed = None
    except Exception:  # a broken installed definition must not stop a tool that has the text
        installed = None
    if installed is not None and (md5 in ("", "*") or installed._md5sum == md5):
        return installed
    if not definition:
        if installed is not None:
            return installed
        raise DecodeError(f"Cannot load message class for [{type_name}]: it is not installed and "
                          "the publisher sent no message_definition")
    try:
        classes = generate_dynamic(type_name, definition)
    except Exception as exc:
        raise DecodeError(f"Cannot build message class for [{type_name}] from the publisher's "
                          f"message_definition: {exc}") from None
    from minros.msgs import normalize_type

    return classes[normalize_type(type_name)]
