"""The message definitions rosbag2 stores with each type (``ros2msg`` encoding), written and read.

rosbag2 (rosbag2_cpp's LocalMessageDefinitionSource) stores a type as its ``.msg`` text,
then each type it depends on, once, depth first, in the order of their sorted names, each
after a line of 80 ``=`` and a line ``MSG: pkg/Name``. Readers also meet ``MSG: pkg/msg/Name``
(other writers), and ``IDL:`` blocks (types defined in IDL), which minros does not read.
"""

from __future__ import annotations

import re
from typing import List, Set, Tuple

from minros.ros2.types import TypeRegistry

DELIMITER = "=" * 80
_BLOCK = re.compile(r"^={80}\n(MSG|IDL|SRV): *(\S+) *$", re.MULTILINE)


class DefinitionError(ValueError):
    """A stored definition that cannot be read (IDL, or no text)."""


def short(name: str) -> str:
    """``pkg/msg/Name`` -> ``pkg/Name`` (the spelling rosbag2's delimiters use)."""
    parts = name.split("/")
    return f"{parts[0]}/{parts[-1]}" if len(parts) == 3 else name


def full(name: str) -> str:
    """``pkg/Name`` -> ``pkg/msg/Name``; full names stay as they are."""
    parts = name.split("/")
    return f"{parts[0]}/msg/{parts[1]}" if len(parts) == 2 else name


def full_text(registry: TypeRegistry, ros2_type: str) -> str:
    """The ``ros2msg`` definition of ``ros2_type`` with everything it depends on, as rosbag2
    writes it."""
    seen: Set[str] = set()

    def append(name: str) -> str:
        struct = registry.message(name)
        text = struct.text or _text_of(struct)
        for dep in sorted(struct.dependencies(), key=short):
            if dep not in seen:
                seen.add(dep)
                text += "\n" + DELIMITER + "\nMSG: " + short(dep) + "\n" + append(dep)
        return text

    return append(ros2_type)


def _text_of(struct) -> str:  # noqa: ANN001 - a MessageType without source text (derived)
    from minros.ros2.types.mapping import ros2_msg_text

    return ros2_msg_text(struct.fields, struct.constants)


def split(root_type: str, text: str) -> List[Tuple[str, str]]:
    """``[(pkg/msg/Name, .msg text), ...]`` of a stored definition, the root first."""
    if not text.strip():
        raise DefinitionError("the bag stores no message definition for it")
    blocks: List[Tuple[str, str, str]] = []
    name, kind, start = full(root_type), "MSG", 0
    if text.startswith(DELIMITER):  # an IDL definition starts with its delimiter
        first = _BLOCK.match(text)
        if first is not None:
            kind, name, start = first.group(1), full(first.group(2)), first.end() + 1
    for match in _BLOCK.finditer(text, start):
        blocks.append((kind, name, text[start:match.start()]))
        kind, name, start = match.group(1), full(match.group(2)), match.end() + 1
    blocks.append((kind, name, text[start:]))
    if any(k != "MSG" for k, _n, _t in blocks):
        raise DefinitionError("its stored definition is IDL, which minros does not read "
                              "(only .msg definitions, encoding ros2msg)")
    return [(n, t if t.endswith("\n") or not t else t + "\n") for _k, n, t in blocks]
