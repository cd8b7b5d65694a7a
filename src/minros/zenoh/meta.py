"""What a minros bridge tells other minros bridges about a topic it carries out of ROS.

zenoh-bridge-ros1 sends bytes and a type name: the local publisher it advertises for a remote
topic has no ``message_definition`` (so ``rostopic echo``, ``rosbag record`` and web tools
that decode by it fail without the ``.msg`` files) and is never latched. A minros bridge
answers a query on ``keys.meta_key(...)`` with this record:

    b"MRZ1" | uint32 little-endian n | n bytes of UTF-8 JSON | the latched message, if any

the JSON being ``{"type", "md5sum", "definition", "latching", "latched"}`` ("latched" says
whether a message follows, as a message may be empty). Bridges that do not know the key never
see it; a record that does not parse is ignored with one log line.
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from typing import Any, Optional

__all__ = ["MAGIC", "MAX_JSON", "MetaError", "TopicMeta", "decode", "encode"]

MAGIC = b"MRZ1"
#: a definition is a few kB; the JSON of one is refused beyond this
MAX_JSON = 1 << 20
_U32 = struct.Struct("<I")


class MetaError(ValueError):
    pass


@dataclass(frozen=True)
class TopicMeta:
    type: str
    md5sum: str
    definition: str = ""
    latching: bool = False
    #: the last message of a latched topic (serialized, without length), or None
    latched: Optional[bytes] = None


def encode(meta: TopicMeta) -> bytes:
    head = json.dumps({"type": meta.type, "md5sum": meta.md5sum, "definition": meta.definition,
                       "latching": meta.latching, "latched": meta.latched is not None},
                      separators=(",", ":")).encode("utf-8")
    return b"".join([MAGIC, _U32.pack(len(head)), head, meta.latched or b""])


def decode(data: Any) -> TopicMeta:
    """The record in ``data`` (bytes-like); MetaError saying what is wrong otherwise."""
    data = bytes(data)
    if data[:4] != MAGIC or len(data) < 8:
        raise MetaError("not a minros topic record")
    (size,) = _U32.unpack_from(data, 4)
    if size > MAX_JSON or 8 + size > len(data):
        raise MetaError(f"its JSON claims {size} bytes of {len(data) - 8}")
    try:
        fields = json.loads(data[8:8 + size].decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as exc:
        raise MetaError(f"its JSON does not parse: {exc}") from None
    if not isinstance(fields, dict):
        raise MetaError("its JSON is not an object")
    kinds = {"type": str, "md5sum": str, "definition": str, "latching": bool, "latched": bool}
    for name, kind in kinds.items():
        if not isinstance(fields.get(name), kind):
            raise MetaError(f"its field '{name}' is missing or not a {kind.__name__}")
    rest = data[8 + size:]
    if rest and not fields["latched"]:
        raise MetaError(f"{len(rest)} bytes follow a record without a latched message")
    return TopicMeta(fields["type"], fields["md5sum"], fields["definition"], fields["latching"],
                     rest if fields["latched"] else None)
