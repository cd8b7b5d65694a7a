"""rosgraph.impl.graph: the ROS graph as rqt_graph polls it, from the master and the nodes.

:class:`Graph` asks the master for the system state (nodes, topics, services) and each node
for its bus info (``getBusInfo``: the connections it has now), then keeps

* ``nn_nodes``, ``nt_nodes`` (topics as graph nodes: a leading space, see :func:`topic_node`),
  ``srvs``;
* ``nt_all_edges`` (node <-> topic, as the master registered them), ``nt_edges`` (node <->
  topic, as connected), ``nn_edges`` (node -> node, labelled by topic);
* ``bad_nodes``: nodes that did not answer, DEAD until they answer again (then WONKY).

Every call to a peer is bounded (1 s per node, 0.2 s for a node already known bad); a master
answer is kept ``master_stale`` seconds, a node's ``node_stale`` seconds.
"""

from __future__ import annotations

import itertools
import logging
import random
import sys
import threading
import time
from typing import Dict, Iterator, List, Optional, Set, Tuple

from minros.tools.master import Master, MasterException
from minros.wire.rosapi import RemoteError
from minros.wire.slaveapi import SlaveClient

logger = logging.getLogger("rosgraph.graph")

#: the caller id the graph's queries carry
_ROS_NAME = "/rosviz"


def topic_node(topic: str) -> str:
    """The graph node of a topic: the name after a space, which no ROS node name can be."""
    return " " + topic


def node_topic(node: str) -> str:
    """The topic of a graph node made by :func:`topic_node`."""
    return node[1:]


class BadNode:
    """A node that did not answer (DEAD) or answers only sometimes (WONKY)."""

    DEAD = 0
    WONKY = 1

    def __init__(self, name: str, type: int, reason: str) -> None:  # noqa: A002 - ROS's name
        self.name = name
        self.reason = reason
        self.type = type


class Edge:
    """``start -> end``, labelled (a topic for node-to-node edges); equal when the ends are."""

    __slots__ = ["start", "end", "label", "key", "rkey"]

    def __init__(self, start: str, end: str, label: str = "") -> None:
        self.start = start
        self.end = end
        self.label = label
        self.key = f"{start}|{label}"
        self.rkey = f"{end}|{label}"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Edge) and (self.start, self.end) == (other.start, other.end)

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]

    def __str__(self) -> str:
        return f"{self.start}->{self.end}"


def edge_args(start: str, dest: str, direction: str, label: str) -> List[Tuple[str, str, str]]:
    """The ``Edge`` arguments for a connection seen from ``start``: ``o`` out, ``i`` in,
    ``b`` both."""
    args = []
    if direction in ("o", "b"):
        args.append((start, dest, label))
    if direction in ("i", "b"):
        args.append((dest, start, label))
    return args


class EdgeList:
    """Edges indexed by their start and by their end (so a node's edges go at once)."""

    __slots__ = ["edges_by_start", "edges_by_end"]

    def __init__(self) -> None:
        self.edges_by_start: Dict[str, List[Edge]] = {}
        self.edges_by_end: Dict[str, List[Edge]] = {}

    def __iter__(self) -> Iterator[Edge]:
        return itertools.chain(*self.edges_by_start.values())

    def __contains__(self, edge: Edge) -> bool:
        return edge in self.edges_by_start.get(edge.key, ())

    def has(self, edge: Edge) -> bool:
        return edge in self

    def add(self, edge: Edge) -> bool:
        """Add ``edge``; whether it was new."""
        added = False
        for index, key in ((self.edges_by_start, edge.key), (self.edges_by_end, edge.rkey)):
            edges = index.setdefault(key, [])
            if edge not in edges:
                edges.append(edge)
                added = True
        return added

    def add_edges(self, start: Optional[str], dest: Optional[str], direction: str,
                  label: str = "") -> bool:
        """Add the edges of one connection (see :func:`edge_args`); whether any was new. An
        end that is not known yet (stale data) is logged and skipped."""
        if not start:
            logger.warning("cannot add edge: cannot map start [%s] to a node name", start)
            return False
        if not dest:
            logger.warning("cannot add edge: cannot map dest [%s] to a node name", dest)
            return False
        updated = False
        for args in edge_args(start, dest, direction, label):
            updated = self.add(Edge(*args)) or updated
        return updated

    def delete(self, edge: Edge) -> None:
        for index, key in ((self.edges_by_start, edge.key), (self.edges_by_end, edge.rkey)):
            edges = index.get(key)
            if edges and edge in edges:
                edges.remove(edge)

    def delete_all(self, node: str) -> None:
        """Delete every edge that starts or ends at ``node``."""
        prefix = node + "|"
        doomed = [e for index in (self.edges_by_start, self.edges_by_end)
                  for key, edges in index.items() if key.startswith(prefix) for e in edges]
        for edge in doomed:
            self.delete(edge)


class Graph:
    """The graph below ``node_ns`` and ``topic_ns``, refreshed by :meth:`update`. One thread
    calls update(); bad_update() may run in another (the bad-node table is locked)."""

    def __init__(self, node_ns: str = "/", topic_ns: str = "/") -> None:
        self.master = Master(_ROS_NAME)
        self.node_ns = node_ns or "/"
        self.topic_ns = topic_ns or "/"
        self.nn_nodes: Set[str] = set()
        self.nt_nodes: Set[str] = set()
        self.bad_nodes: Dict[str, BadNode] = {}
        self.bad_nodes_lock = threading.Lock()
        self.srvs: Set[str] = set()
        self.nn_edges = EdgeList()
        self.nt_edges = EdgeList()
        self.nt_all_edges = EdgeList()
        self.node_uri_map: Dict[str, str] = {}
        self.uri_node_map: Dict[str, str] = {}
        self.last_master_refresh = 0.0
        self.last_node_refresh: Dict[str, float] = {}
        self.master_stale = 5.0
        self.node_stale = 5.0

    def set_master_stale(self, stale_secs: float) -> None:
        self.master_stale = stale_secs

    def set_node_stale(self, stale_secs: float) -> None:
        self.node_stale = stale_secs

    # -- the master

    def _master_refresh(self) -> bool:
        try:
            pubs, subs, srvs = self.master.getSystemState()
        except (MasterException, OSError) as exc:
            print("Unable to contact master", str(exc), file=sys.stderr)
            logger.error("unable to contact master: %s", exc)
            return False
        updated = False
        nodes: Set[str] = set()
        for state, direction in ((pubs, "o"), (subs, "i")):
            for topic, topic_nodes in state:
                if not topic.startswith(self.topic_ns):
                    continue
                nodes.update(n for n in topic_nodes if n.startswith(self.node_ns))
                self.nt_nodes.add(topic_node(topic))
                for node in topic_nodes:
                    updated = self.nt_all_edges.add_edges(node, topic_node(topic), direction) or updated
        services = {name for name, _ in srvs}
        gone = self.nn_nodes - nodes
        if nodes != self.nn_nodes:
            self.nn_nodes = nodes
            updated = True
        if services != self.srvs:
            self.srvs = services
            updated = True
        for node in gone:
            logger.debug("purging edges for node %s", node)
            for edges in (self.nn_edges, self.nt_edges, self.nt_all_edges):
                edges.delete_all(node)
        return updated

    # -- the nodes

    def _mark_bad_node(self, node: str, reason: str) -> None:
        with self.bad_nodes_lock:
            if node in self.bad_nodes:
                self.bad_nodes[node].type = BadNode.DEAD
            else:
                self.bad_nodes[node] = BadNode(node, BadNode.DEAD, reason)

    def _unmark_bad_node(self, node: str, reason: str = "") -> None:
        """A bad node that answered becomes WONKY (it stays on the list)."""
        with self.bad_nodes_lock:
            if node in self.bad_nodes:
                self.bad_nodes[node].type = BadNode.WONKY

    def _node_refresh_businfo(self, node: str, uri: str, bad_node: bool = False) -> bool:
        """Ask ``node`` for its connections and update topics and edges."""
        try:
            with SlaveClient(uri, _ROS_NAME, 0.2 if bad_node else 1.0) as client:
                bus_info = client.get_bus_info()
        except RemoteError as exc:  # it answered, but not with its connections
            if bad_node:
                self._unmark_bad_node(node)
            logger.error("cannot get stats info from node [%s]: %s", node, exc)
            return False
        except Exception as exc:  # noqa: BLE001 - any other failure puts the node on the bad list
            self._mark_bad_node(node, str(exc))
            return False
        if bad_node:
            self._unmark_bad_node(node)
        updated = False
        for info in bus_info:
            if len(info) < 5:  # a node answering garbage
                continue
            _conn_id, dest_id, direction, _transport, topic = info[:5]
            connected = info[5] if len(info) > 5 else True
            if not connected or not topic.startswith(self.topic_ns):
                continue
            self.nt_nodes.add(topic_node(topic))
            updated = self.nt_edges.add_edges(node, topic_node(topic), direction) or updated
            if str(dest_id).startswith("http://"):
                dest = self.uri_node_map.get(dest_id)
                updated = self.nn_edges.add_edges(node, dest, direction, topic) or updated
        return updated

    def _node_uri_refresh(self, node: str) -> Optional[str]:
        try:
            uri = self.master.lookupNode(node)
        except Exception as exc:  # noqa: BLE001 - the node left, or the master is gone
            logger.warning("master reported error in node lookup: %s", exc)
            return None
        self.node_uri_map[node] = uri
        self.uri_node_map[uri] = node
        return uri

    def _node_uri_refresh_all(self) -> None:
        for node in self.nn_nodes:
            self._node_uri_refresh(node)

    def _node_refresh(self, node: str, bad_node: bool = False) -> bool:
        uri = self._node_uri_refresh(node)
        return uri is not None and bool(uri) and self._node_refresh_businfo(node, uri, bad_node)

    def _due(self, node: str) -> bool:
        return time.time() > self.last_node_refresh.get(node, 0.0) + self.node_stale

    def _refreshed(self, node: str) -> None:
        # a random offset (up to a fifth of the interval) spreads the nodes' refreshes out
        self.last_node_refresh[node] = time.time() + random.random() * self.node_stale / 5.0

    def bad_update(self) -> bool:
        """Refresh the nodes on the bad list (kept apart so they do not slow update())."""
        with self.bad_nodes_lock:
            queue = list(self.bad_nodes.values())
        updated = False
        for bad in queue:
            if self._due(bad.name):
                updated = self._node_refresh(bad.name, True) or updated
                self._refreshed(bad.name)
        return updated

    def update(self) -> bool:
        """Refresh from the master (when stale) and from every node that is due; whether
        anything changed."""
        updated = False
        if time.time() > self.last_master_refresh + self.master_stale:
            updated = self._master_refresh()
            if self.last_master_refresh == 0:
                self._node_uri_refresh_all()
            self.last_master_refresh = time.time()
        for node in list(self.nn_nodes):
            if self._due(node):
                updated = self._node_refresh(node) or updated
                self._refreshed(node)
        return updated
