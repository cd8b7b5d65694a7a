"""Callbacks to nodes: asynchronous ``publisherUpdate`` / ``paramUpdate`` / ``shutdown`` /
``graphUpdate`` XML-RPC calls, in order per node, in parallel across nodes, each bounded."""

from __future__ import annotations

import collections
import threading
from typing import Any, Callable, Deque, Dict, List, OrderedDict, Set, Tuple

from minros.master.log import log as _log
from minros.wire.slaveapi import SlaveClient

#: the caller id of every call the master makes to a node
MASTER_CALLER_ID = "/master"

#: Timeout of one callback (publisherUpdate, paramUpdate, shutdown) to a node, in seconds.
CALLBACK_TIMEOUT = 5.0
CALLBACK_WORKERS = 16  # started on demand; many slow nodes do not stall the others
#: Bound on callbacks queued for one node (a node that never answers cannot grow memory forever).
MAX_QUEUED_PER_NODE = 10000
#: Queued calls to one node beyond which a newer update replaces a queued one for the same key.
COALESCE_BACKLOG = 32


class CallbackPool:
    """Asynchronous XML-RPC calls to nodes.

    Calls to one node API run one at a time, in order; different nodes proceed in parallel on
    ``workers`` threads. Once a node has a backlog (``COALESCE_BACKLOG``), a queued call with the
    same coalescing key (e.g. ``publisherUpdate`` for one topic) is replaced by the newer one, so a
    slow node gets the latest state rather than an ever-growing queue. Each call is bounded by
    ``timeout``.

    ``args`` are the call's XML-RPC parameters as on the wire, the caller id (``/master``)
    first; the calls go through one :class:`~minros.wire.slaveapi.SlaveClient` per node, kept
    alive (the 256 most recent), which fills the caller id in itself. ``on_result`` gets the
    node's answer as it came (the triplet), or the exception the call ended in.
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
        self._proxies: OrderedDict[str, SlaveClient] = collections.OrderedDict()
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
            node = self._proxies.pop(api, None)
            if node is None:
                node = SlaveClient(api, MASTER_CALLER_ID, timeout=self.timeout)
            self._proxies[api] = node
            while len(self._proxies) > 256:
                _old_api, old = self._proxies.popitem(last=False)
                old.close()
        # args[0] is the caller id, which the client sends itself
        return node.raw(method, *args[1:])

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
