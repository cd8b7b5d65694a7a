"""``minros trace dissector``: a Lua dissector for Wireshark and tshark that decodes TCPROS
message bodies by type.

The dissector itself (``dissector.lua`` beside this module) needs nothing from minros at run
time: it reads the ``message_definition`` that a publisher's connection header carries and
decodes that topic's frames with it, nested types, arrays, strings and times included. What a
capture cannot say is written into the file here: service headers name their type but carry
no definition, so the service types named with ``--type`` or found in the trace files given
are embedded (their request and response full texts, from minros's message registry), and so
are message types named with ``--type`` (for a publisher that sends no definition).

Pure: type names and trace events in, Lua text out.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import resources
from typing import Any, Dict, Iterable, List, Tuple

__all__ = ["KnownTypes", "UnknownType", "known_types", "lua_source", "types_in_events"]

MARKER = "-- @KNOWN_TYPES@"


class UnknownType(LookupError):
    """A type named with ``--type`` that minros does not know (the text says why)."""


@dataclass
class KnownTypes:
    """Definitions to embed: ``messages`` type -> (md5sum, full text), ``services`` type ->
    (md5sum, request full text, response full text)."""

    messages: Dict[str, Tuple[str, str]] = field(default_factory=dict)
    services: Dict[str, Tuple[str, str, str]] = field(default_factory=dict)


def known_types(names: Iterable[str], quiet: bool = False) -> KnownTypes:
    """The definitions of ``names`` (message or service types, as minros finds them). With
    ``quiet``, names minros does not know are left out instead of raising
    :class:`UnknownType`."""
    from minros.msgs import UnknownTypeError, get_message_class, get_service_class

    known = KnownTypes()
    for name in names:
        try:
            srv = get_service_class(name)
        except (UnknownTypeError, ValueError):
            srv = None
        if srv is not None:
            known.services[name] = (srv._md5sum, srv._request_class._full_text,
                                    srv._response_class._full_text)
            continue
        try:
            cls = get_message_class(name)
        except (UnknownTypeError, ValueError) as exc:
            if quiet:
                continue
            raise UnknownType(f"{name} is neither a message nor a service type minros knows "
                              f"({exc})") from None
        known.messages[name] = (cls._md5sum, cls._full_text)
    return known


def types_in_events(events: Iterable[Dict[str, Any]]) -> List[str]:
    """The service types (``type`` of a service server's connection header) named in trace
    events, in the order first seen: their definitions are what a capture lacks."""
    found: List[str] = []
    for ev in events:
        if ev.get("ev") != "tcpros.header" or "service" not in ev:
            continue
        fields = {pair[0]: pair[1] for pair in ev.get("fields") or [] if len(pair) == 2}
        name = fields.get("type", "")
        if name and name != "*" and "/" in name and name not in found:
            found.append(name)
    return found


def _long_string(text: str) -> str:
    """``text`` as a Lua long string whose brackets it does not contain."""
    level = 0
    while f"]{'=' * level}]" in text:
        level += 1
    eq = "=" * level
    # a newline right after the opening bracket is skipped by Lua: keep the text's own
    return f"[{eq}[\n{text}]{eq}]"


def _table(known: KnownTypes) -> str:
    lines = []
    for name, (md5, text) in sorted(known.messages.items()):
        lines.append(f'KNOWN.messages["{name}"] = {{md5 = "{md5}", definition = '
                     f"{_long_string(text)}}}")
    for name, (md5, request, response) in sorted(known.services.items()):
        lines.append(f'KNOWN.services["{name}"] = {{md5 = "{md5}",\n  request = '
                     f"{_long_string(request)},\n  response = {_long_string(response)}}}")
    return "\n".join(lines) if lines else "-- (none)"


def lua_source(known: KnownTypes | None = None, version: str = "") -> str:
    """The dissector, with ``known``'s definitions embedded."""
    template = resources.files("minros.tools.trace").joinpath("dissector.lua").read_text(
        encoding="utf-8")
    if MARKER not in template:  # pragma: no cover - the template ships with the marker
        raise RuntimeError("dissector.lua lacks its KNOWN_TYPES marker")
    text = template.replace(MARKER, _table(known or KnownTypes()), 1)
    return text.replace("@MINROS_VERSION@", version or "unknown")
