"""What a node offers and asks for: publications, subscriptions, services, parameter
subscriptions (rospy's topic and service managers, for one node).

The registries are plain maps under one lock, a leaf: nothing here calls out. The hot paths
read them without the lock (``dict.get`` is atomic under the GIL); every change and every
listing takes it. The interfaces the node needs of a publication and a subscription are the
Protocols below; ``minros.client`` implements them.
"""

from __future__ import annotations

import logging
import threading
import traceback
from typing import Any, Callable, Dict, List, Protocol, Set, Tuple

from minros.exceptions import ServiceException
from minros.transport.base import PublicationSide
from minros.wire import admission

__all__ = ["ParamUpdateHandler", "Publication", "Registries", "ServiceHandler", "Subscription"]

_logger = logging.getLogger("minros.node")


class Publication(PublicationSide, Protocol):
    """What the node needs of a publication (``minros.client.publication`` implements it)."""

    def get_stats(self) -> List[Any]: ...
    def get_stats_info(self) -> List[Any]: ...
    def close(self) -> None: ...


class Subscription(Protocol):
    """What the node needs of a subscription (``minros.client.subscription`` implements it)."""

    resolved_name: str
    type: str

    def publisher_update(self, uris: List[str]) -> None: ...
    def get_stats(self) -> List[Any]: ...
    def get_stats_info(self) -> List[Any]: ...
    def close(self) -> None: ...


#: ``handler(stream, header, conn)``: serves one inbound service connection and owns its
#: stream; ``conn`` (an admission.Connection) is its part in the TCPROS server's admission
ServiceHandler = Callable[[Any, Dict[str, str], admission.Connection], Any]
#: ``handler(key, value) -> bool``: a paramUpdate; True when the value was cached
ParamUpdateHandler = Callable[[str, Any], bool]


class Registries:
    """The node's registries; ``lock`` guards every change and listing (a leaf)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.publications: Dict[str, Publication] = {}
        self.subscriptions: Dict[str, Subscription] = {}
        self.services: Dict[str, ServiceHandler] = {}
        self.param_subscriptions: Set[str] = set()
        self._param_update_handlers: List[ParamUpdateHandler] = []

    # -- topics ------------------------------------------------------------------------------

    def add_publication(self, pub: Publication) -> None:
        with self.lock:
            self.publications[pub.resolved_name] = pub

    def remove_publication(self, pub: Publication) -> bool:
        """Whether ``pub`` was the registered one (and is gone now)."""
        with self.lock:
            if self.publications.get(pub.resolved_name) is not pub:
                return False
            del self.publications[pub.resolved_name]
            return True

    def add_subscription(self, sub: Subscription) -> None:
        with self.lock:
            self.subscriptions[sub.resolved_name] = sub

    def remove_subscription(self, sub: Subscription) -> bool:
        """Whether ``sub`` was the registered one (and is gone now)."""
        with self.lock:
            if self.subscriptions.get(sub.resolved_name) is not sub:
                return False
            del self.subscriptions[sub.resolved_name]
            return True

    def endpoints(self) -> Tuple[List[Publication], List[Subscription]]:
        with self.lock:
            return list(self.publications.values()), list(self.subscriptions.values())

    def publication_types(self) -> Dict[str, Tuple[str, str]]:
        """topic -> (type, md5sum) of every publication (for a header naming another topic)."""
        with self.lock:
            return {t: (p.type, p.md5sum) for t, p in self.publications.items()}

    # -- services ----------------------------------------------------------------------------

    def add_service(self, resolved_name: str, handler: ServiceHandler) -> None:
        """ServiceException if ``resolved_name`` is served already (no two winners)."""
        with self.lock:
            if resolved_name in self.services:
                raise ServiceException(f"service [{resolved_name}] already registered")
            self.services[resolved_name] = handler

    def remove_service(self, resolved_name: str) -> bool:
        with self.lock:
            return self.services.pop(resolved_name, None) is not None

    # -- parameters --------------------------------------------------------------------------

    def add_param_subscription(self, key: str) -> None:
        with self.lock:
            self.param_subscriptions.add(key)

    def add_param_update_handler(self, handler: ParamUpdateHandler) -> None:
        with self.lock:
            self._param_update_handlers.append(handler)

    def param_update_handlers(self) -> List[ParamUpdateHandler]:
        with self.lock:
            return list(self._param_update_handlers)

    def param_update(self, key: str, value: Any) -> bool:
        """A paramUpdate from the master: True if the node cares about ``key``."""
        cached = False
        for handler in self.param_update_handlers():
            try:
                cached = bool(handler(key, value)) or cached
            except Exception:
                _logger.error("paramUpdate handler failed: %s", traceback.format_exc())
        if cached:
            return True
        prefix = key.rstrip("/") + "/"
        with self.lock:
            return any(k == key or k.startswith(prefix) or key.startswith(k.rstrip("/") + "/")
                       for k in self.param_subscriptions)

    def snapshot(self) -> Tuple[List[Tuple[str, str]], List[Tuple[str, str]], List[str], List[str]]:
        """(publications, subscriptions) as (topic, type), services, parameter keys: what
        a (re-)registration registers."""
        with self.lock:
            return ([(t, p.type) for t, p in self.publications.items()],
                    [(t, s.type) for t, s in self.subscriptions.items()],
                    list(self.services), list(self.param_subscriptions))
