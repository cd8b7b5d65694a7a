"""rospy.service's internals: the service record and the service manager."""

from __future__ import annotations

from typing import Any

from minros import node as _node

from .registration import ServiceManager  # noqa: F401


class _Service:
    """What rospy records of a service: names, classes, URI (set once served)."""

    def __init__(self, name: str, service_class: Any) -> None:
        self.resolved_name = _node.resolve_name(name)
        self.service_class = service_class
        self.request_class = service_class._request_class
        self.response_class = service_class._response_class
        self.uri = None


ServiceImpl = _Service
