"""The master's registrations (pure): publishers, subscribers, services and parameter
subscriptions by key, and the node table; a node that registers again from a new URI bumps
the old one (rosmaster.registrations' shape and names)."""

from __future__ import annotations

from typing import Any, Callable, Dict, Iterable, List, Tuple

Caller = Tuple[str, str]  # (caller_id, caller_api)


class InternalException(Exception):
    """A bug in the master's own bookkeeping (an unknown registration kind)."""



class Registrations:
    """``{key: [(caller_id, caller_api), ...]}`` in registration order; services also keep
    ``{service: (caller_id, service_api)}`` (one provider per service, last one wins)."""

    TOPIC_SUBSCRIPTIONS = 1
    TOPIC_PUBLICATIONS = 2
    SERVICE = 3
    PARAM_SUBSCRIPTIONS = 4

    def __init__(self, type_: int) -> None:
        if type_ not in _KINDS:
            raise InternalException(f"invalid registration type: {type_}")
        self.type = type_
        self.map: Dict[str, List[Caller]] = {}
        # None until the first service registration (rosmaster's messages depend on it)
        self.service_api_map: Dict[str, Caller] | None = None

    def __bool__(self) -> bool:
        return bool(self.map)

    __nonzero__ = __bool__  # rosmaster's (Python 2) name, which its tests call

    def __contains__(self, key: str) -> bool:
        return key in self.map

    def has_key(self, key: str) -> bool:
        return key in self.map

    def __getitem__(self, key: str) -> List[Caller]:
        return self.map.get(key, [])

    def keys(self) -> Iterable[str]:
        return self.map.keys()

    iterkeys = keys

    def get_apis(self, key: str) -> List[str]:
        return [api for _id, api in self.map.get(key, ())]

    def get_service_api(self, service: str) -> str | None:
        entry = self.service_api_map.get(service) if self.service_api_map else None
        return entry[1] if entry else None

    def get_state(self) -> List[List[Any]]:
        return [[key, [cid for cid, _api in callers]] for key, callers in self.map.items()]

    def register(self, key: str, caller_id: str, caller_api: str,
                 service_api: str | None = None) -> None:
        if service_api:
            self.map[key] = [(caller_id, caller_api)]
            if self.service_api_map is None:
                self.service_api_map = {}
            self.service_api_map[key] = (caller_id, service_api)
            return
        if self.type == Registrations.SERVICE:
            raise InternalException("service_api must be specified for Registrations.SERVICE")
        callers = self.map.get(key)
        if callers is None:
            self.map[key] = [(caller_id, caller_api)]
        elif (caller_id, caller_api) not in callers:
            callers.append((caller_id, caller_api))

    def unregister_all(self, caller_id: str) -> None:
        dead = []
        for key, callers in self.map.items():
            callers[:] = [c for c in callers if c[0] != caller_id]
            if not callers:
                dead.append(key)
        for key in dead:
            del self.map[key]
        if self.service_api_map:
            for key in [k for k, v in self.service_api_map.items() if v[0] == caller_id]:
                del self.service_api_map[key]

    def unregister(self, key: str, caller_id: str, caller_api: str | None,
                   service_api: str | None = None) -> List[Any]:
        if service_api:
            if self.service_api_map is None:
                return [1, f"[{caller_id}] is not a provider of [{key}]", 0]
            if self.service_api_map.get(key) != (caller_id, service_api):
                return [1, f"[{service_api}] is no longer the current service api handle for [{key}]", 0]
            del self.service_api_map[key]
            del self.map[key]
            return [1, f"Unregistered [{caller_id}] as provider of [{key}]", 1]
        if self.type == Registrations.SERVICE:
            raise InternalException("service_api must be specified for Registrations.SERVICE")
        callers = self.map.get(key, [])
        if caller_api is not None and (caller_id, caller_api) in callers:
            callers.remove((caller_id, caller_api))
            if not callers:
                del self.map[key]
            return [1, f"Unregistered [{caller_id}] as provider of [{key}]", 1]
        return [1, f"[{caller_id}] is not a known provider of [{key}]", 0]


class NodeRef:
    """What one node (caller_id) has registered, by kind; the node is forgotten when this is
    empty (rosmaster's attribute names)."""

    def __init__(self, id: str, api: str) -> None:  # noqa: A002 - rosmaster's name
        self.id = id
        self.api = api
        self.clear()

    def clear(self) -> None:
        """Forget every registration (the API stays)."""
        self.param_subscriptions: List[str] = []
        self.topic_subscriptions: List[str] = []
        self.topic_publications: List[str] = []
        self.services: List[str] = []

    def _keys(self, type_: int) -> List[str]:
        if type_ == Registrations.TOPIC_SUBSCRIPTIONS:
            return self.topic_subscriptions
        if type_ == Registrations.TOPIC_PUBLICATIONS:
            return self.topic_publications
        if type_ == Registrations.SERVICE:
            return self.services
        if type_ == Registrations.PARAM_SUBSCRIPTIONS:
            return self.param_subscriptions
        raise InternalException(f"invalid registration type: {type_}")

    def add(self, type_: int, key: str) -> None:
        keys = self._keys(type_)
        if key not in keys:
            keys.append(key)

    def remove(self, type_: int, key: str) -> None:
        keys = self._keys(type_)
        if key in keys:
            keys.remove(key)

    def is_empty(self) -> bool:
        return not (self.param_subscriptions or self.topic_subscriptions
                    or self.topic_publications or self.services)


_KINDS = (Registrations.TOPIC_SUBSCRIPTIONS, Registrations.TOPIC_PUBLICATIONS,
          Registrations.SERVICE, Registrations.PARAM_SUBSCRIPTIONS)


class RegistrationManager:
    """All registrations and the node table. Not thread-safe: the handler holds one lock.

    ``on_bump(old_api, caller_id)`` is called when ``caller_id`` registers from a new API; the
    old registrations of ``caller_id`` are purged before the new one is added.
    """

    def __init__(self, on_bump: Callable[[str, str], None] | None = None) -> None:
        self.nodes: Dict[str, NodeRef] = {}
        self.on_bump = on_bump
        self.publishers = Registrations(Registrations.TOPIC_PUBLICATIONS)
        self.subscribers = Registrations(Registrations.TOPIC_SUBSCRIPTIONS)
        self.services = Registrations(Registrations.SERVICE)
        self.param_subscribers = Registrations(Registrations.PARAM_SUBSCRIPTIONS)

    def get_node(self, caller_id: str) -> NodeRef | None:
        return self.nodes.get(caller_id)

    def reverse_lookup(self, caller_api: str) -> List[NodeRef]:
        return [node for node in self.nodes.values() if node.api == caller_api]

    def _register_node_api(self, caller_id: str, caller_api: str) -> Tuple[NodeRef, bool]:
        node = self.nodes.get(caller_id)
        if node is not None:
            if node.api == caller_api:
                return node, False
            if self.on_bump is not None:
                self.on_bump(node.api, caller_id)
        bumped = node is not None
        node = self.nodes[caller_id] = NodeRef(caller_id, caller_api)
        return node, bumped

    def _register(self, regs: Registrations, key: str, caller_id: str, caller_api: str,
                  service_api: str | None = None) -> None:
        node, bumped = self._register_node_api(caller_id, caller_api)
        node.add(regs.type, key)
        if bumped:
            for r in (self.publishers, self.subscribers, self.services, self.param_subscribers):
                r.unregister_all(caller_id)
        regs.register(key, caller_id, caller_api, service_api)

    def _unregister(self, regs: Registrations, key: str, caller_id: str, caller_api: str | None,
                    service_api: str | None = None) -> List[Any]:
        node = self.nodes.get(caller_id)
        if node is None:
            return [1, f"[{caller_id}] is not a registered node", 0]
        result = regs.unregister(key, caller_id, caller_api, service_api)
        if result[2] == 1:
            node.remove(regs.type, key)
        if node.is_empty():
            del self.nodes[caller_id]
        return result

    def register_publisher(self, topic: str, caller_id: str, caller_api: str) -> None:
        self._register(self.publishers, topic, caller_id, caller_api)

    def register_subscriber(self, topic: str, caller_id: str, caller_api: str) -> None:
        self._register(self.subscribers, topic, caller_id, caller_api)

    def register_service(self, service: str, caller_id: str, caller_api: str,
                         service_api: str) -> None:
        self._register(self.services, service, caller_id, caller_api, service_api)

    def register_param_subscriber(self, key: str, caller_id: str, caller_api: str) -> None:
        self._register(self.param_subscribers, key, caller_id, caller_api)

    def unregister_publisher(self, topic: str, caller_id: str, caller_api: str) -> List[Any]:
        return self._unregister(self.publishers, topic, caller_id, caller_api)

    def unregister_subscriber(self, topic: str, caller_id: str, caller_api: str) -> List[Any]:
        return self._unregister(self.subscribers, topic, caller_id, caller_api)

    def unregister_service(self, service: str, caller_id: str, service_api: str) -> List[Any]:
        return self._unregister(self.services, service, caller_id, None, service_api)

    def unregister_param_subscriber(self, key: str, caller_id: str, caller_api: str) -> List[Any]:
        return self._unregister(self.param_subscribers, key, caller_id, caller_api)
