"""Which web pages and host names may use ``minros web``: the Origin and Host checks.

A browser lets any page it shows open a WebSocket to ``ws://localhost:9090`` and send requests
there; without these checks a page on any site could publish, call services and set
parameters on the ROS graph of whoever opens it. Browsers name the page's site in the
``Origin`` header of such requests, so the server accepts a request only when it has no
``Origin`` (roslibpy, scripts, tools: never a page) or when the page is

* one of the server's own (its origin's host and port are the request's ``Host``),
* served from this machine (``localhost``, ``*.localhost``, ``127.0.0.0/8``, ``::1``), or
* from a site the user allowed with ``--allow-origin`` / :data:`ENV_VAR` (a Foxglove,
  Lichtblick or webviz app hosted elsewhere), as Jupyter's ``allow_origin`` does.

A page that makes a name of its own resolve to 127.0.0.1 (DNS rebinding) passes as "its own
origin", so the ``Host`` header is checked first: an IP address (a rebinding needs a name), a
loopback name, or a name of this machine (its host name, ``<host name>.local``,
ROS_HOSTNAME, the address the server is bound to) or of an allowed origin. ``null`` (sandboxed
frames, ``file://`` pages) is refused unless allowed by name, since any site can make one.

Pure functions over header values: no sockets.
"""

from __future__ import annotations

import ipaddress
import urllib.parse
from typing import Iterable, Optional, Sequence, Set, Tuple

#: the environment variable holding more allowed origins (comma or space separated)
ENV_VAR = "MINROS_WEB_ALLOW_ORIGIN"
OPTION = "--allow-origin"
_DEFAULT_PORTS = {"http": 80, "ws": 80, "https": 443, "wss": 443}


class OriginError(ValueError):
    """An ``--allow-origin`` value that is not an origin."""


def split_values(text: str) -> list:
    """The origins of :data:`ENV_VAR`'s value (commas or whitespace between them)."""
    return [part for part in text.replace(",", " ").split() if part]


def _host_port(netloc: str) -> Optional[Tuple[str, Optional[int]]]:
    """``"Host:80"`` -> ``("host", 80)``, ``"[::1]"`` -> ``("::1", None)``; None if malformed."""
    try:
        parsed = urllib.parse.urlsplit("//" + netloc)
        host, port = parsed.hostname, parsed.port
    except ValueError:
        return None
    if not host or parsed.username is not None or parsed.path or parsed.query or parsed.fragment:
        return None
    return host.rstrip(".").lower(), port


def parse_origin(text: str) -> Optional[Tuple[str, str, int]]:
    """``(scheme, host, port)`` of a serialized origin (``https://app.foxglove.dev``), the
    port made explicit; None when ``text`` is not one."""
    scheme, sep, rest = text.strip().partition("://")
    scheme = scheme.lower()
    if not sep or scheme not in _DEFAULT_PORTS or not rest or "/" in rest.rstrip("/"):
        return None
    found = _host_port(rest.rstrip("/"))
    if found is None:
        return None
    host, port = found
    return scheme, host, port if port is not None else _DEFAULT_PORTS[scheme]


def normalize(text: str) -> str:
    """The canonical text of an ``--allow-origin`` value; OriginError naming the form."""
    text = text.strip()
    if text in ("*", "null"):
        return text
    parsed = parse_origin(text)
    if parsed is None:
        raise OriginError(f"{OPTION} {text!r} is not an origin: give scheme://host[:port] "
                          "(no path), e.g. https://app.foxglove.dev, or * for any")
    scheme, host, port = parsed
    shown = f"[{host}]" if ":" in host else host
    return f"{scheme}://{shown}:{port}"


def is_loopback_name(host: str) -> bool:
    if host == "localhost" or host.endswith(".localhost"):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _is_ip(host: str) -> bool:
    try:
        ipaddress.ip_address(host)
        return True
    except ValueError:
        return False


class OriginPolicy:
    """The checks of one server (see the module doc). ``allow``: the ``--allow-origin``
    values; ``local_names``: the names this machine answers to (host name, ROS_HOSTNAME, the
    bound address)."""

    def __init__(self, allow: Sequence[str] = (), local_names: Iterable[str] = ()) -> None:
        values = [normalize(a) for a in allow]
        self.allow_any = "*" in values
        self.allow_null = "null" in values
        self.allowed: Set[Tuple[str, str, int]] = set()
        self.names: Set[str] = set()
        #: the machine's own names (not the allowed origins')
        self.local_names: Set[str] = set()
        for value in values:
            parsed = parse_origin(value) if value not in ("*", "null") else None
            if parsed is not None:
                self.allowed.add(parsed)
                self.names.add(parsed[1])
        for name in local_names:
            if name:
                self.names.add(name.rstrip(".").lower())
                self.local_names.add(name.rstrip(".").lower())

    def host_error(self, host_header: Optional[str]) -> Optional[str]:
        """Why a request with this ``Host`` is refused, or None (no header: not a browser)."""
        if host_header is None or self.allow_any:
            return None
        found = _host_port(host_header.strip())
        if found is None:
            return f"minros web: the Host header {host_header[:100]!r} is malformed"
        host = found[0]
        if _is_ip(host) or is_loopback_name(host) or host in self.names:
            return None
        return (f"minros web: refused the host name {host[:100]!r}, which is not a name of this "
                f"server (a page of another site may have made it point here): open the server "
                f"by its address or as localhost, or start it with {OPTION} "
                f"http://{host_header.strip()[:100]} if that name is yours")

    def origin_error(self, origin: Optional[str], host_header: Optional[str]) -> Optional[str]:
        """Why a request from a page of ``origin`` is refused, or None."""
        if origin is None or self.allow_any:
            return None
        shown = origin.strip()[:100]
        if shown == "null":
            if self.allow_null:
                return None
            return ("minros web: refused a page of origin null (a file:// page or a sandboxed "
                    "frame, which any site can make): serve the page over http, or start the "
                    f"server with {OPTION} null")
        parsed = parse_origin(origin)
        if parsed is not None and self._accepted(parsed, host_header):
            return None
        return (f"minros web: refused a page of {shown}: only this server's own pages and "
                f"pages on localhost may use it; start it with {OPTION} {shown} to allow "
                "that site")

    def _accepted(self, origin: Tuple[str, str, int], host_header: Optional[str]) -> bool:
        scheme, host, port = origin
        if scheme in ("http", "https") and is_loopback_name(host):
            return True
        if origin in self.allowed:
            return True
        if host_header is not None:  # the server's own page: the origin names the Host
            found = _host_port(host_header.strip())
            if found is not None and found[0] == host:
                return found[1] == port or (found[1] is None and port == _DEFAULT_PORTS[scheme])
        return False

    def local_page(self, origin: Optional[str], host_header: Optional[str]) -> bool:
        """Whether a request comes from this machine's user, for what only they may do
        (start the Learn view's exercises, which run programs here): a client that is no page
        (no ``Origin``), a page on localhost, or the server's own page opened by an address
        or a name of this machine. Not a page let in by ``--allow-origin`` alone, nor, under
        ``*`` (which turns the Host check off, so a rebound name passes as the server's
        own), one opened by a name the machine does not have."""
        if origin is None:
            return True
        parsed = parse_origin(origin)
        if parsed is None or parsed[0] not in ("http", "https"):
            return False  # null (file:// pages, sandboxed frames), ws:, ...
        scheme, host, port = parsed
        if is_loopback_name(host):
            return True
        found = _host_port(host_header.strip()) if host_header is not None else None
        if found is None or found[0] != host:
            return False
        if found[1] != port and not (found[1] is None and port == _DEFAULT_PORTS[scheme]):
            return False
        return _is_ip(host) or host in self.local_names

    def cors_origin(self, origin: Optional[str], host_header: Optional[str]) -> Optional[str]:
        """The ``Access-Control-Allow-Origin`` value for a request (the page's own origin when
        it may read the answer; never ``*``), or None."""
        if origin is None or self.origin_error(origin, host_header) is not None:
            return None
        return origin.strip()
