"""The ROS master: Master API, Parameter Server API and callbacks to nodes.

``python -m minros.master [-p PORT]`` runs it like ``rosmaster --core`` (no rosout, no roscore
parameters; ``minros core`` adds those).

Layout, from pure to I/O:

* :class:`ParamTree` — the parameter dictionary (nested dicts keyed by resolved names),
  :func:`compute_param_updates`, which decides who gets which ``paramUpdate``, and
  :class:`ParamDictionary`, the two with the subscriptions (rosmaster.paramserver's shape);
* :class:`Registrations` / :class:`RegistrationManager` — publishers, subscribers, services,
  parameter subscriptions and the node table (same name + new URI bumps the old node);
* :class:`CallbackPool` — asynchronous ``publisherUpdate`` / ``paramUpdate`` / ``shutdown`` calls
  to nodes: a few worker threads, at most one call in flight per node and calls to one node
  in order, each call bounded by a timeout; a slow or dead node never delays an API reply;
* :class:`MasterHandler` — the XML-RPC methods with rosmaster's argument validation and exact
  ``[code, statusMessage, value]`` results, plus one minros extension: ``subscribeGraph`` /
  ``unsubscribeGraph``, after which the master calls ``graphUpdate(caller_id, version)`` on the
  subscriber's URI whenever a registration changes (``minros web`` pushes its graph that way;
  against rosmaster, which has no such method, it polls);
* :class:`Master` — handler + :class:`minros.wire.xmlrpc.XmlRpcServer`.
"""

from __future__ import annotations

import argparse
import collections
import copy
import functools
import logging
import os
import signal
import sys
import threading
from typing import Any, Callable, Deque, Dict, Iterable, List, OrderedDict, Set, Tuple

from minros import logfiles, rosenv
from minros.names import ANYTYPE, GLOBALNS, SEP, canonicalize_name, is_global, is_private, ns_join
from minros.names import resolve_name as _resolve_name
from minros.signals import SignalWatch
from minros.wire import trace, xmlrpc
from minros.wire.rosapi import (
    api,
    empty_or_valid_name,
    is_api,
    is_topic,
    non_empty_str,
    not_none,
    valid_name,
    valid_type_name,
)

DEFAULT_MASTER_PORT = 11311
#: Timeout of one callback (publisherUpdate, paramUpdate, shutdown) to a node, in seconds.
CALLBACK_TIMEOUT = 5.0
CALLBACK_WORKERS = 16  # started on demand; many slow nodes do not stall the others
#: Bound on callbacks queued for one node (a node that never answers cannot grow memory forever).
MAX_QUEUED_PER_NODE = 10000
#: Queued calls to one node beyond which a newer update replaces a queued one for the same key.
COALESCE_BACKLOG = 32
#: Bound on graph watchers (subscribeGraph), so the table cannot be grown without limit.
MAX_GRAPH_WATCHERS = 256

#: What the master did (+PUB, -SUB, +PARAM ... as in rosmaster's master.log); no handler is
#: attached unless :func:`configure_log_file` is called, so library use stays silent.
_log = logging.getLogger("minros.master")
_log.propagate = False

Caller = Tuple[str, str]  # (caller_id, caller_api)


# ====================================================================== parameter tree (pure)


def _key_parts(key: str) -> List[str]:
    return [part for part in key.split(SEP) if part]


def _subscription_key(key: str) -> str:
    """Parameter subscriptions are stored canonical *with* a trailing slash (``/a/b/``)."""
    return key if key == SEP else canonicalize_name(key) + SEP


class ParamTree:
    """Nested-dict parameter storage with rosmaster's semantics (not thread-safe by itself)."""

    def __init__(self) -> None:
        self.root: Dict[str, Any] = {}

    def get(self, key: str) -> Any:
        """Value at the resolved ``key`` (a dict for a namespace); KeyError when unset."""
        value: Any = self.root
        if key != GLOBALNS:
            # The first segment is skipped, as rosmaster does: for a global key it is the empty
            # root; for the odd relative key a non-global caller_id produces it is dropped.
            for part in [p for p in key.split(SEP)[1:] if p]:
                if type(value) is not dict:
                    raise KeyError(key)
                value = value[part]
        return value

    def has(self, key: str) -> bool:
        try:
            self.get(key)
        except KeyError:
            return False
        return True

    def set(self, key: str, value: Any) -> None:
        """Set ``key``; a dict replaces the whole namespace; scalars on the path become namespaces."""
        if key == GLOBALNS:
            if type(value) is not dict:
                raise TypeError("cannot set root of parameter tree to non-dictionary")
            self.root = value
            return
        parts = _key_parts(key)
        node = self.root
        for part in parts[:-1]:
            child = node.get(part)
            if type(child) is not dict:
                # implicit conversion of a value (or nothing) to a namespace
                child = node[part] = {}
            node = child
        node[parts[-1]] = value

    def delete(self, key: str) -> None:
        """Delete ``key``; KeyError when it is not set (or is the root)."""
        if key == GLOBALNS:
            raise KeyError("cannot delete root of parameter tree")
        parts = _key_parts(key)
        node: Any = self.root
        for part in parts[:-1]:
            if type(node) is not dict or part not in node:
                raise KeyError(key)
            node = node[part]
        # Like rosmaster, the last step is plain Python: under a scalar parent this raises
        # TypeError (reported as "invalid arguments"), not KeyError.
        if parts[-1] not in node:
            raise KeyError(key)
        del node[parts[-1]]

    def names(self) -> List[str]:
        """Every leaf key, global; namespaces themselves (and empty dicts) are not listed."""
        out: List[str] = []

        def walk(prefix: str, tree: Dict[str, Any]) -> None:
            for k, v in tree.items():
                if type(v) is dict:
                    walk(ns_join(prefix, k), v)
                else:
                    out.append(ns_join(prefix, k))

        walk(GLOBALNS, self.root)
        return out

    def search(self, ns: str, key: str) -> str | None:
        """searchParam: the caller's private namespace first, then each ancestor namespace.

        Matching is on the first segment of ``key``; the returned full key may not exist yet.
        """
        if not key or is_private(key):
            raise ValueError("invalid key")
        if not is_global(ns):
            raise ValueError("namespace must be global")
        if is_global(key):
            return key if self.has(key) else None
        key_ns = _key_parts(key)[0]
        if self.has(ns_join(ns, key_ns)):
            return ns_join(ns, key)
        namespaces = _key_parts(ns)
        for i in range(1, len(namespaces) + 1):
            if self.has(SEP + SEP.join(namespaces[:-i] + [key_ns])):
                return SEP + SEP.join(namespaces[:-i] + [key])
        return None


def _all_subkeys(param_key: str, value: Dict[str, Any], out: List[str]) -> List[str]:
    for k, v in value.items():
        sub = ns_join(param_key, k) + SEP
        out.append(sub)
        if type(v) is dict:
            _all_subkeys(sub, v, out)
    return out


def compute_param_updates(subscriptions: Registrations, param_key: str, param_value: Any,
                          caller_to_ignore: str | None = None
                          ) -> List[Tuple[List[Caller], str, Any]]:
    """Who gets which ``paramUpdate`` after ``param_key`` changed to ``param_value``.

    * subscribers of ``S/`` with ``K/`` inside ``S/`` get ``(K/, value)`` (the setter excluded);
    * when a dict is set (a delete is the dict ``{}``), subscribers below ``K/`` whose key is absent
      from the new dict get ``(key, {})`` and those present get their own sub-value.
    """
    if not subscriptions:
        return []
    param_key = _subscription_key(param_key)
    all_keys = _all_subkeys(param_key, param_value, []) if type(param_value) is dict else None
    present = set(all_keys) if all_keys is not None else set()
    updates: List[Tuple[List[Caller], str, Any]] = []
    for sub_key in subscriptions.keys():
        ns_key = sub_key if sub_key.endswith(SEP) else sub_key + SEP
        if param_key.startswith(ns_key):
            callers = subscriptions[sub_key]
            if caller_to_ignore is not None:
                callers = [c for c in callers if c[0] != caller_to_ignore]
            updates.append((callers, param_key, param_value))
        elif all_keys is not None and ns_key.startswith(param_key) and sub_key not in present:
            updates.append((subscriptions[sub_key], sub_key, {}))
    if all_keys is not None:
        for key in all_keys:
            if key in subscriptions:
                value: Any = param_value
                for part in _key_parts(key[len(param_key):]):
                    value = value[part]
                updates.append((subscriptions[key], key, value))
    return updates


def _snapshot(value: Any) -> Any:
    """A copy of a namespace (dicts are the only values the tree mutates in place)."""
    return copy.deepcopy(value) if type(value) is dict else value


class ParamDictionary:
    """The parameter server's state: the tree and who subscribed to what (rosmaster's
    ParamDictionary). ``notify_task(updates)`` receives :func:`compute_param_updates`' answer
    after a change, under the lock (so updates reach the queue in the order of the changes)."""

    def __init__(self, reg_manager: RegistrationManager, lock: Any = None) -> None:
        self.lock = lock if lock is not None else threading.RLock()
        self.tree = ParamTree()
        self.reg_manager = reg_manager

    @property
    def parameters(self) -> Dict[str, Any]:
        return self.tree.root

    def get_param_names(self) -> List[str]:
        with self.lock:
            return self.tree.names()

    def search_param(self, ns: str, key: str) -> str | None:
        with self.lock:
            return self.tree.search(ns, key)

    def get_param(self, key: str) -> Any:
        """KeyError when unset."""
        with self.lock:
            return self.tree.get(key)

    def has_param(self, key: str) -> bool:
        with self.lock:
            return self.tree.has(key)

    def set_param(self, key: str, value: Any, notify_task: Callable[[List[Any]], Any] | None = None,
                  caller_id: str | None = None) -> None:
        """Set ``key`` (the setter, ``caller_id``, is not told of its own change)."""
        with self.lock:
            self.tree.set(key, value)
            if notify_task:
                updates = compute_param_updates(self.reg_manager.param_subscribers, key, value,
                                                caller_id)
                if updates:
                    notify_task(updates)

    def delete_param(self, key: str, notify_task: Callable[[List[Any]], Any] | None = None) -> None:
        """KeyError when ``key`` is not set; subscribers learn it as the value ``{}``."""
        with self.lock:
            self.tree.delete(key)
            if notify_task:
                updates = compute_param_updates(self.reg_manager.param_subscribers, key, {})
                if updates:
                    notify_task(updates)

    def subscribe_param(self, key: str, registration_args: Tuple[str, str]) -> Any:
        """Subscribe ``(caller_id, caller_api)`` to ``key``; its value now, ``{}`` if unset."""
        key = _subscription_key(key)
        with self.lock:
            try:
                value = self.tree.get(key)
            except KeyError:
                value = {}
            self.reg_manager.register_param_subscriber(key, *registration_args)
            return value

    def unsubscribe_param(self, key: str, unregistration_args: Tuple[str, str]) -> List[Any]:
        with self.lock:
            return self.reg_manager.unregister_param_subscriber(_subscription_key(key),
                                                               *unregistration_args)


# ====================================================================== registrations (pure)


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


# ====================================================================== callbacks to nodes


class CallbackPool:
    """Asynchronous XML-RPC calls to nodes.

    Calls to one node API run one at a time, in order; different nodes proceed in parallel on
    ``workers`` threads. Once a node has a backlog (``COALESCE_BACKLOG``), a queued call with the
    same coalescing key (e.g. ``publisherUpdate`` for one topic) is replaced by the newer one, so a
    slow node gets the latest state rather than an ever-growing queue. Each call is bounded by
    ``timeout``.
    """

    def __init__(self, workers: int = CALLBACK_WORKERS, timeout: float = CALLBACK_TIMEOUT,
                 call: Callable[[str, str, Tuple[Any, ...]], Any] | None = None) -> None:
        self.workers = workers
        self.timeout = timeout
        self._call = call or self._xmlrpc_call
        mutex = threading.RLock()
        self._lock = threading.Condition(mutex)  # work to do
        self._drained = threading.Condition(mutex)  # nothing queued or in flight
        # api -> deque of [coalesce_key, method, args, on_result]
        self._queues: Dict[str, Deque[Any]] = {}
        self._ready: Deque[str] = collections.deque()  # apis with work and not in flight
        self._busy: Set[str] = set()
        self._threads: List[threading.Thread] = []
        self._stopped = False
        self._proxies: OrderedDict[str, Any] = collections.OrderedDict()
        self._proxies_lock = threading.Lock()

    def queue(self, api: str, method: str, args: Tuple[Any, ...], coalesce: Any | None = None,
              on_result: Callable[[Any], None] | None = None) -> None:
        with self._lock:
            if self._stopped:
                return
            q = self._queues.get(api)
            if q is None:
                q = self._queues[api] = collections.deque()
            if coalesce is not None and len(q) >= COALESCE_BACKLOG:
                # Only a node that is not keeping up gets merged updates; others get every
                # call, in order, exactly as rosmaster sends them.
                # The newer update goes to the back (so it is the last one for its key) and
                # the most recent older one for the same key is dropped.
                for index in range(len(q) - 1, -1, -1):
                    if q[index][0] == coalesce:
                        del q[index]
                        break
            if len(q) >= MAX_QUEUED_PER_NODE:
                q.popleft()  # drop the oldest: this node is not keeping up anyway
            q.append([coalesce, method, args, on_result])
            if api not in self._busy and len(q) == 1:
                self._ready.append(api)
            if len(self._threads) < self.workers and len(self._ready) > self._idle_count():
                self._spawn()
            self._lock.notify()

    def _idle_count(self) -> int:
        return len(self._threads) - len(self._busy)

    def _spawn(self) -> None:
        t = threading.Thread(target=self._worker, name="master-callbacks", daemon=True)
        self._threads.append(t)
        t.start()

    def _worker(self) -> None:
        while True:
            with self._lock:
                while not self._ready and not self._stopped:
                    self._lock.wait()
                if self._stopped:
                    return
                api = self._ready.popleft()
                q = self._queues[api]
                _key, method, args, on_result = q.popleft()
                self._busy.add(api)
            try:
                result = self._call(api, method, args)
            except Exception as exc:  # noqa: BLE001 - a dead node is normal: logged, not raised
                result = exc
                self._forget_proxy(api)
                _log.info("%s -> %s failed: %s", method, api, exc)
            if on_result is not None:
                try:
                    on_result(result)
                except Exception:  # noqa: BLE001 - never let a callback kill the worker
                    pass
            with self._lock:
                self._busy.discard(api)
                if self._queues.get(api):
                    self._ready.append(api)
                    self._lock.notify()
                else:
                    self._queues.pop(api, None)
                    if not self._busy and not self._queues:
                        self._drained.notify_all()

    def _xmlrpc_call(self, api: str, method: str, args: Tuple[Any, ...]) -> Any:
        with self._proxies_lock:
            proxy = self._proxies.pop(api, None)
            if proxy is None:
                proxy = xmlrpc.ServerProxy(api, timeout=self.timeout)
            self._proxies[api] = proxy
            while len(self._proxies) > 256:
                _old_api, old = self._proxies.popitem(last=False)
                old.close()
        return getattr(proxy, method)(*args)

    def _forget_proxy(self, api: str) -> None:
        with self._proxies_lock:
            proxy = self._proxies.pop(api, None)
        if proxy is not None:
            proxy.close()

    def pending(self) -> int:
        with self._lock:
            return sum(len(q) for q in self._queues.values()) + len(self._busy)

    def join(self, timeout: float | None = None) -> bool:
        """Wait until every queued callback has been made; False if ``timeout`` ran out."""
        with self._lock:
            return self._drained.wait_for(lambda: not self._busy and not self._queues, timeout)

    def stop(self) -> None:
        with self._lock:
            self._stopped = True
            self._queues.clear()
            self._ready.clear()
            self._lock.notify_all()
        with self._proxies_lock:
            for proxy in self._proxies.values():
                proxy.close()
            self._proxies.clear()


# ====================================================================== the API


class MasterHandler:
    """Master and Parameter Server XML-RPC API. Every public method is an API call."""

    def __init__(self, pool: CallbackPool | None = None) -> None:
        self._uri = ""
        self._pool = pool if pool is not None else CallbackPool()
        self._lock = threading.RLock()
        self._reg = RegistrationManager(on_bump=self._bump_node)
        self._params = ParamDictionary(self._reg, self._lock)
        self._topic_types: Dict[str, str] = {}
        self._shutdown_requested = threading.Event()
        self._on_shutdown: Callable[[str], None] | None = None
        #: graph watchers: api -> caller_id; a watcher has at most one graphUpdate in flight
        #: and is sent the newest version when it answers (so a burst costs it two calls)
        self._graph_version = 0
        self._graph_watchers: Dict[str, str] = {}
        self._graph_sent: Dict[str, int] = {}

    # -- internal (not callable over XML-RPC: leading underscore)

    def _set_uri(self, uri: str) -> None:
        self._uri = uri

    def _bump_node(self, old_api: str, caller_id: str) -> None:
        _log.warning("new node registered with same name [%s]: shutting down %s", caller_id, old_api)
        self._pool.queue(old_api, "shutdown",
                         ("/master", f"[{caller_id}] Reason: new node registered with same name"))

    def _notify_topic_subscribers(self, topic: str) -> None:
        pub_uris = self._reg.publishers.get_apis(topic)
        for sub_api in self._reg.subscribers.get_apis(topic):
            self._pool.queue(sub_api, "publisherUpdate", ("/master", topic, pub_uris),
                             coalesce=("publisherUpdate", topic))

    def _notify_param_subscribers(self, updates: List[Tuple[List[Caller], str, Any]]) -> None:
        for callers, key, value in updates:
            value = _snapshot(value)  # the tree's own dict may change before the call is made
            for _caller_id, caller_api in callers:
                self._pool.queue(caller_api, "paramUpdate", ("/master", key, value),
                                 coalesce=("paramUpdate", key),
                                 on_result=functools.partial(self._param_update_result, caller_api,
                                                             key))

    def _graph_changed(self) -> None:
        """A registration changed (called with ``_lock`` held): tell the graph watchers."""
        self._graph_version += 1
        for watcher_api in self._graph_watchers:
            self._send_graph_update(watcher_api)

    def _send_graph_update(self, watcher_api: str) -> None:
        if watcher_api in self._graph_sent:
            return  # one in flight: its answer sends the newest version
        self._graph_sent[watcher_api] = self._graph_version
        self._pool.queue(watcher_api, "graphUpdate", ("/master", self._graph_version),
                         on_result=functools.partial(self._graph_update_result, watcher_api))

    def _graph_update_result(self, watcher_api: str, result: Any) -> None:
        with self._lock:
            sent = self._graph_sent.pop(watcher_api, None)
            ok = isinstance(result, (list, tuple)) and len(result) == 3 and result[0] == 1
            if not ok:
                # gone, or no longer interested: a watcher subscribes again when it wants more
                if self._graph_watchers.pop(watcher_api, None) is not None:
                    _log.info("-GRAPH %s (graphUpdate answered %r)", watcher_api, result)
                return
            if watcher_api in self._graph_watchers and sent != self._graph_version:
                self._send_graph_update(watcher_api)

    def _param_update_result(self, caller_api: str, key: str, result: Any) -> None:
        # A node answering -1 is not (or no longer) subscribed: stop sending it updates.
        if isinstance(result, (list, tuple)) and len(result) == 3 and result[0] == -1:
            with self._lock:
                for node in self._reg.reverse_lookup(caller_api):
                    self._reg.unregister_param_subscriber(key, node.id, caller_api)

    # -- process

    @api(0, (None,))
    def shutdown(self, caller_id: str, msg: str) -> Any:
        if msg:
            print(f"shutdown request: {msg}", flush=True)
        else:
            print("shutdown requst", flush=True)
        self._shutdown_requested.set()
        if self._on_shutdown is not None:
            self._on_shutdown(f"external shutdown request from [{caller_id}]: {msg}")
        return 1, "shutdown", 0

    @api("")
    def getUri(self, caller_id: str) -> Any:
        return 1, "", self._uri

    @api(-1)
    def getPid(self, caller_id: str) -> Any:
        return 1, "", os.getpid()

    # -- parameter server

    @api(0, (non_empty_str("key"),))
    def deleteParam(self, caller_id: str, key: str) -> Any:
        key = _resolve_name(key, caller_id)
        with self._lock:
            try:
                self._params.delete_param(key, self._notify_param_subscribers)
            except KeyError:
                return -1, f"parameter [{key}] is not set", 0
        _log.info("-PARAM [%s] by %s", key, caller_id)
        return 1, f"parameter {key} deleted", 0

    @api(0, (non_empty_str("key"), not_none("value")))
    def setParam(self, caller_id: str, key: str, value: Any) -> Any:
        key = _resolve_name(key, caller_id)
        with self._lock:
            self._params.set_param(key, value, self._notify_param_subscribers, caller_id)
        _log.info("+PARAM [%s] by %s", key, caller_id)
        return 1, f"parameter {key} set", 0

    @api(0, (non_empty_str("key"),))
    def getParam(self, caller_id: str, key: str) -> Any:
        key = _resolve_name(key, caller_id)
        with self._lock:
            try:
                value = self._params.get_param(key)
            except KeyError:
                return -1, f"Parameter [{key}] is not set", 0
            # a namespace is marshalled after the lock is released: hand out a snapshot so a
            # concurrent setParam below it cannot change the dict mid-serialization
            return 1, f"Parameter [{key}]", _snapshot(value)

    @api(0, (non_empty_str("key"),))
    def searchParam(self, caller_id: str, key: str) -> Any:
        with self._lock:
            found = self._params.search_param(caller_id, key)
        if found:
            return 1, f"Found [{found}]", found
        return -1, f"Cannot find parameter [{key}] in an upwards search", ""

    @api(0, (is_api("caller_api"), non_empty_str("key")))
    def subscribeParam(self, caller_id: str, caller_api: str, key: str) -> Any:
        key = _resolve_name(key, caller_id)
        with self._lock:
            value = _snapshot(self._params.subscribe_param(key, (caller_id, caller_api)))
        _log.info("+CACHEDPARAM [%s] by %s", key, caller_id)
        return 1, f"Subscribed to parameter [{key}]", value

    @api(0, (is_api("caller_api"), non_empty_str("key")))
    def unsubscribeParam(self, caller_id: str, caller_api: str, key: str) -> Any:
        key = _resolve_name(key, caller_id)
        with self._lock:
            self._params.unsubscribe_param(key, (caller_id, caller_api))
        _log.info("-CACHEDPARAM [%s] by %s", key, caller_id)
        return 1, f"Unsubscribe to parameter [{key}]", 1

    @api(False, (non_empty_str("key"),))
    def hasParam(self, caller_id: str, key: str) -> Any:
        key = _resolve_name(key, caller_id)
        with self._lock:
            return 1, key, self._params.has_param(key)

    @api([])
    def getParamNames(self, caller_id: str) -> Any:
        with self._lock:
            return 1, "Parameter names", self._params.get_param_names()

    # -- services

    @api(0, (is_topic("service"), is_api("service_api"), is_api("caller_api")))
    def registerService(self, caller_id: str, service: str, service_api: str,
                        caller_api: str) -> Any:
        with self._lock:
            self._reg.register_service(service, caller_id, caller_api, service_api)
            self._graph_changed()
        _log.info("+SERVICE [%s] %s %s", service, caller_id, caller_api)
        return 1, f"Registered [{caller_id}] as provider of [{service}]", 1

    @api("", (is_topic("service"),))
    def lookupService(self, caller_id: str, service: str) -> Any:
        with self._lock:
            uri = self._reg.services.get_service_api(service)
        if uri:
            return 1, f"rosrpc URI: [{uri}]", uri
        return -1, "no provider", ""

    @api(0, (is_topic("service"), is_api("service_api")))
    def unregisterService(self, caller_id: str, service: str, service_api: str) -> Any:
        with self._lock:
            result = self._reg.unregister_service(service, caller_id, service_api)
            if result[2]:
                self._graph_changed()
        _log.info("-SERVICE [%s] %s %s", service, caller_id, service_api)
        return result

    # -- topics

    @api([], (is_topic("topic"), valid_type_name("topic_type"), is_api("caller_api")))
    def registerSubscriber(self, caller_id: str, topic: str, topic_type: str,
                           caller_api: str) -> Any:
        with self._lock:
            self._reg.register_subscriber(topic, caller_id, caller_api)
            if topic not in self._topic_types and topic_type != ANYTYPE:
                self._topic_types[topic] = topic_type
            pub_uris = self._reg.publishers.get_apis(topic)
            self._graph_changed()
        _log.info("+SUB [%s] %s %s", topic, caller_id, caller_api)
        return 1, f"Subscribed to [{topic}]", pub_uris

    @api(0, (is_topic("topic"), is_api("caller_api")))
    def unregisterSubscriber(self, caller_id: str, topic: str, caller_api: str) -> Any:
        with self._lock:
            result = self._reg.unregister_subscriber(topic, caller_id, caller_api)
            if result[2]:
                self._graph_changed()
        _log.info("-SUB [%s] %s %s", topic, caller_id, caller_api)
        return result

    @api([], (is_topic("topic"), valid_type_name("topic_type"), is_api("caller_api")))
    def registerPublisher(self, caller_id: str, topic: str, topic_type: str,
                          caller_api: str) -> Any:
        with self._lock:
            self._reg.register_publisher(topic, caller_id, caller_api)
            # '*' never squashes a known type; a real type replaces an older one
            if topic_type != ANYTYPE or topic not in self._topic_types:
                self._topic_types[topic] = topic_type
            self._notify_topic_subscribers(topic)
            sub_uris = self._reg.subscribers.get_apis(topic)
            self._graph_changed()
        _log.info("+PUB [%s] %s %s", topic, caller_id, caller_api)
        return 1, f"Registered [{caller_id}] as publisher of [{topic}]", sub_uris

    @api(0, (is_topic("topic"), is_api("caller_api")))
    def unregisterPublisher(self, caller_id: str, topic: str, caller_api: str) -> Any:
        with self._lock:
            result = self._reg.unregister_publisher(topic, caller_id, caller_api)
            if result[2]:
                self._notify_topic_subscribers(topic)
                self._graph_changed()
        _log.info("-PUB [%s] %s %s", topic, caller_id, caller_api)
        return result

    # -- graph introspection

    @api(0, (is_api("caller_api"),))
    def subscribeGraph(self, caller_id: str, caller_api: str) -> Any:
        """minros extension: call ``graphUpdate(caller_id, version)`` on ``caller_api`` after
        every registration change; the value is the current version."""
        with self._lock:
            if caller_api not in self._graph_watchers and len(self._graph_watchers) >= MAX_GRAPH_WATCHERS:
                return -1, f"too many graph watchers ({MAX_GRAPH_WATCHERS}): poll getSystemState", 0
            self._graph_watchers[caller_api] = caller_id
            version = self._graph_version
        _log.info("+GRAPH [%s] %s", caller_id, caller_api)
        return 1, "Subscribed to graph changes", version

    @api(0, (is_api("caller_api"),))
    def unsubscribeGraph(self, caller_id: str, caller_api: str) -> Any:
        with self._lock:
            known = self._graph_watchers.pop(caller_api, None) is not None
        _log.info("-GRAPH [%s] %s", caller_id, caller_api)
        return 1, "Unsubscribed from graph changes", int(known)

    @api("", (valid_name("node"),))
    def lookupNode(self, caller_id: str, node_name: str) -> Any:
        with self._lock:
            node = self._reg.get_node(node_name)
            if node is not None:
                return 1, "node api", node.api
        return -1, f"unknown node [{node_name}]", ""

    @api(0, (empty_or_valid_name("subgraph"),))
    def getPublishedTopics(self, caller_id: str, subgraph: str) -> Any:
        if subgraph and not subgraph.endswith(SEP):
            subgraph += SEP
        with self._lock:
            topics = [[t, self._topic_types[t]] for t in self._reg.publishers.keys()
                      if t.startswith(subgraph)]
        return 1, "current topics", topics

    @api([])
    def getTopicTypes(self, caller_id: str) -> Any:
        with self._lock:
            return 1, "current system state", [[t, ty] for t, ty in self._topic_types.items()]

    @api([[], [], []])
    def getSystemState(self, caller_id: str) -> Any:
        with self._lock:
            state = [self._reg.publishers.get_state(), self._reg.subscribers.get_state(),
                     self._reg.services.get_state()]
        return 1, "current system state", state


# ====================================================================== the process


class Master:
    """A running master: handler, callback pool and XML-RPC server."""

    def __init__(self, port: int = DEFAULT_MASTER_PORT, host: str | None = None,
                 workers: int = CALLBACK_WORKERS, callback_timeout: float = CALLBACK_TIMEOUT,
                 hostname: str | None = None) -> None:
        """``host``: address to bind (default: ROS's rule from ROS_IP/ROS_HOSTNAME);
        ``hostname``: name advertised in the master URI (default: ROS_HOSTNAME/ROS_IP/host name)."""
        allowed = rosenv.allowed_hosts()  # first: ValueError naming a malformed entry
        self.hostname = hostname
        if host is None and hostname is not None:
            host = rosenv.get_bind_address(hostname)
        self.pool = CallbackPool(workers, callback_timeout)
        self.handler = MasterHandler(self.pool)
        self._stopped = threading.Event()
        # Stop once the reply to the shutdown call has reached the caller.
        self.handler._on_shutdown = lambda reason: xmlrpc.after_reply(self._stopped.set)
        bind = rosenv.get_bind_address() if host is None else host
        self.server = xmlrpc.XmlRpcServer(self.handler, bind, port,
                                          ipv6=":" in bind or rosenv.use_ipv6(), allowed=allowed,
                                          on_refused=_report_refusal, what="the master")
        self.uri = ""

    def start(self) -> Master:
        self.server.start()
        if self.hostname:
            self.uri = f"http://{self.hostname}:{self.server.port}/"
        else:
            self.uri = rosenv.create_local_xmlrpc_uri(self.server.port)
        self.handler._set_uri(self.uri)
        trace.set_node("/master", self.uri, self.uri)
        return self

    @property
    def port(self) -> int:
        return self.server.port

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the master is stopped (by :meth:`stop` or the ``shutdown`` API)."""
        return self._stopped.wait(timeout)

    def ok(self) -> bool:
        return not self._stopped.is_set()

    def stop(self) -> None:
        self._stopped.set()
        self.server.shutdown()
        self.pool.stop()


def _report_refusal(peer: str, reason: str) -> None:
    """A peer outside ROS_ALLOWED_HOSTS: one line on the console and in master.log (at most
    one a minute per peer, by the admission policy)."""
    _log.warning("%s", reason)
    try:
        sys.stderr.write(f"[WARN] {reason}\n")
    except (OSError, ValueError):
        pass


def configure_log_file(path: str) -> bool:
    """Write the master's log to ``path`` (rosmaster's master.log), rotated as rospy rotates
    it (50 MB, 4 old files) with lines truncated (a caller_id is the client's to choose);
    False if it cannot."""
    try:
        os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
        handler = logfiles.rotating_handler(path, "[%(name)s][%(levelname)s] %(asctime)s: %(message)s")
    except OSError:
        return False
    _log.addHandler(handler)
    _log.setLevel(logging.INFO)
    return True


def install_stop_signals(stop: Callable[[], None]) -> None:
    """SIGINT/SIGTERM stop the master cleanly (no traceback), from a thread of their own."""
    SignalWatch(lambda _signum: stop(), "master-signals").install((signal.SIGINT, signal.SIGTERM))


def main(argv: List[str] | None = None, prog: str = "minros master") -> int:
    """``rosmaster --core`` equivalent."""
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog=prog, description="Run a ROS master (no rosout).")
    parser.add_argument("--core", action="store_true", help="accepted for rosmaster compatibility")
    parser.add_argument("-p", "--port", type=int, default=DEFAULT_MASTER_PORT,
                        help=f"port to listen on (default {DEFAULT_MASTER_PORT})")
    parser.add_argument("-w", "--numworkers", type=int, default=CALLBACK_WORKERS,
                        help="threads making callbacks to nodes")
    parser.add_argument("-t", "--timeout", type=float, default=CALLBACK_TIMEOUT,
                        help="timeout of one callback to a node, in seconds")
    parser.add_argument("--master-logger-level", default=None, help="accepted and ignored")
    args, rest = parser.parse_known_args(argv)
    log_path = ""
    for extra in rest:
        if extra.startswith("__log:="):
            log_path = os.path.abspath(extra[len("__log:="):])
        else:
            parser.error(f"unrecognized arg: {extra}")
    if not 0 < args.port < 65536:
        parser.error(f"invalid port {args.port}")
    try:
        master = Master(args.port, workers=max(1, args.numworkers), callback_timeout=args.timeout)
    except ValueError as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1
    try:
        master.start()
    except OSError as exc:
        print(f"{prog}: cannot listen on port {args.port}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    configure_log_file(log_path or str(rosenv.ros_log_dir() / "master.log"))
    _log.info("Master initialized: port[%s], uri[%s]", master.port, master.uri)
    install_stop_signals(master._stopped.set)
    try:
        while not master.wait(1.0):
            pass
    finally:
        master.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main(prog="python -m minros.master"))
