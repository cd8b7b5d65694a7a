"""The Master and Parameter Server XML-RPC API: one method per rosmaster call, with
rosmaster's argument validation and exact ``[code, statusMessage, value]`` results, and the
``subscribeGraph`` extension (see the package's docstring)."""

from __future__ import annotations

import functools
import os
import threading
from typing import Any, Callable, Dict, List, Tuple

from minros.master.callbacks import MASTER_CALLER_ID, CallbackPool
from minros.master.log import log as _log
from minros.master.params import ParamDictionary, _snapshot
from minros.master.registrations import Caller, RegistrationManager
from minros.names import ANYTYPE, SEP
from minros.names import resolve_name as _resolve_name
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

#: Bound on graph watchers (subscribeGraph), so the table cannot be grown without limit.
MAX_GRAPH_WATCHERS = 256


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
                         (MASTER_CALLER_ID, f"[{caller_id}] Reason: new node registered with same name"))

    def _notify_topic_subscribers(self, topic: str) -> None:
        pub_uris = self._reg.publishers.get_apis(topic)
        for sub_api in self._reg.subscribers.get_apis(topic):
            self._pool.queue(sub_api, "publisherUpdate", (MASTER_CALLER_ID, topic, pub_uris),
                             coalesce=("publisherUpdate", topic))

    def _notify_param_subscribers(self, updates: List[Tuple[List[Caller], str, Any]]) -> None:
        for callers, key, value in updates:
            value = _snapshot(value)  # the tree's own dict may change before the call is made
            for _caller_id, caller_api in callers:
                self._pool.queue(caller_api, "paramUpdate", (MASTER_CALLER_ID, key, value),
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
        self._pool.queue(watcher_api, "graphUpdate", (MASTER_CALLER_ID, self._graph_version),
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
