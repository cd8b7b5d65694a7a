"""rosmaster.util: XML-RPC proxies on nodes, bounded (minros.wire.xmlrpc)."""

from __future__ import annotations

import threading
from typing import Optional
from urllib.parse import urlparse

from minros.wire.xmlrpc import ServerProxy

_proxies = threading.local()  # one proxy per URI and thread, as rosmaster caches them


def xmlrpcapi(uri: Optional[str]) -> Optional[ServerProxy]:
    """A proxy on ``uri``, or None when it is not a URI."""
    if uri is None:
        return None
    parsed = urlparse(uri)
    if not parsed.scheme or not parsed.netloc:
        return None
    if uri not in _proxies.__dict__:
        _proxies.__dict__[uri] = ServerProxy(uri)
    return _proxies.__dict__[uri]


def remove_server_proxy(uri: str) -> None:
    proxy = _proxies.__dict__.pop(uri, None)
    if proxy is not None:
        proxy.close()


def close_half_closed_sockets() -> None:
    """minros's proxies drop a connection the peer closed when they next use it."""
