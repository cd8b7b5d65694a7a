"""What a bridge bridges, from its local ROS graph and the remote resources: a pure function.

zenoh-bridge-ros1's rules in its default ``auto`` mode (``topic_bridge.rs``,
``bridges_storage.rs``), with minros's choices where the bridge has none:

- a local publisher (declared ``pub``) is carried out: the bridge subscribes to it and puts
  every message on the topic's key; so is a topic a remote bridge declares a subscriber of.
- a local subscriber (declared ``sub``) is fed: the bridge publishes the topic locally with
  whatever arrives on the key, also from plain Zenoh publishers that send no beacon
  (zenoh-plugin-ros1 issue #92); so is a topic a remote bridge declares a publisher of.
- a local service (declared ``srv``) is answered: a queryable on its key calls it.
- a remote service becomes a local one that queries Zenoh (zenoh-bridge-ros1 does this only
  with ``CLIENT_BRIDGING_MODE=auto``), unless a local node serves that name: ROS has one
  provider per service name.

What remote beacons alone ask for (a local publisher for a remote one that no local node
subscribes to, a local subscriber for a remote subscriber with no local publisher, a remote
service) is bounded by :func:`limit_remote`: at most ``cap`` such bridges, the first-heard
kept, so that a flood of beacons cannot displace the bridges of the peers heard before it, nor
grow the master and the process without bound; what the local graph asks for is not limited.

The local graph never includes the bridge's own node, so what it publishes for remote
publishers is not declared back. A process has one publisher and one subscriber per topic
name: when several types meet on one name, one is chosen (the local node's) and the others
are reported in ``conflicts``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, FrozenSet, Iterable, List, Mapping, Set, Tuple

from minros.zenoh.keys import Resource

__all__ = ["Plan", "Topic", "limit_remote", "plan", "remote_only"]

#: (name, type, md5sum)
Topic = Tuple[str, str, str]


@dataclass(frozen=True)
class Plan:
    #: beacons to send: the local resources
    declare: FrozenSet[Resource] = frozenset()
    #: topics carried from ROS to Zenoh (a local subscription, a Zenoh publisher)
    outlets: FrozenSet[Topic] = frozenset()
    #: topics carried from Zenoh to ROS (a Zenoh subscription, a local publisher)
    inlets: FrozenSet[Topic] = frozenset()
    #: local services answered on Zenoh (a queryable)
    queryables: FrozenSet[Topic] = frozenset()
    #: remote services offered locally (a local service that queries Zenoh)
    proxies: FrozenSet[Topic] = frozenset()
    #: one text per name on which several types met (one of them is bridged)
    conflicts: Tuple[str, ...] = field(default=())


def _choose(kind: str, wanted: Dict[str, Set[Topic]], preferred: Set[Topic],
            conflicts: List[str]) -> FrozenSet[Topic]:
    chosen = set()
    for name, topics in sorted(wanted.items()):
        if len(topics) == 1:
            chosen |= topics
            continue
        ranked = sorted(topics, key=lambda t: (t not in preferred, t))
        chosen.add(ranked[0])
        others = ", ".join(f"{t[1]} ({t[2]})" for t in ranked[1:])
        conflicts.append(f"{kind} {name} has several types: bridging {ranked[0][1]} "
                         f"({ranked[0][2]}), not {others}")
    return frozenset(chosen)


def plan(local: Iterable[Resource], remote: Iterable[Resource]) -> Plan:
    """The bridges wanted for ``local`` resources (kinds pub, sub, srv of the local graph,
    minus the bridge's own) and the ``remote`` ones heard in beacons."""
    local = frozenset(r for r in local if r.kind in ("pub", "sub", "srv"))
    remote = frozenset(remote)
    out: Dict[str, Set[Topic]] = {}
    into: Dict[str, Set[Topic]] = {}
    for r in local:
        if r.kind == "pub":
            out.setdefault(r.name, set()).add(r.topic)
        elif r.kind == "sub":
            into.setdefault(r.name, set()).add(r.topic)
    for r in remote:
        if r.kind == "sub":
            out.setdefault(r.name, set()).add(r.topic)
        elif r.kind == "pub":
            into.setdefault(r.name, set()).add(r.topic)
    local_pubs = {r.topic for r in local if r.kind == "pub"}
    local_subs = {r.topic for r in local if r.kind == "sub"}
    conflicts: List[str] = []
    outlets = _choose("topic", out, local_pubs, conflicts)
    inlets = _choose("topic", into, local_subs, conflicts)
    served: Dict[str, Set[Topic]] = {}
    for r in local:
        if r.kind == "srv":
            served.setdefault(r.name, set()).add(r.topic)
    queryables = frozenset(t for topics in served.values() for t in topics)
    offered: Dict[str, Set[Topic]] = {}
    for r in remote:
        if r.kind == "srv" and r.name not in served:
            offered.setdefault(r.name, set()).add(r.topic)
    proxies = _choose("service", offered, set(), conflicts)
    return Plan(declare=local, outlets=outlets, inlets=inlets, queryables=queryables,
                proxies=proxies, conflicts=tuple(conflicts))


def remote_only(wanted: Plan, local: Iterable[Resource]) -> Dict[str, FrozenSet[Topic]]:
    """The bridges of ``wanted`` that exist for remote beacons alone, by kind (``inlets``,
    ``outlets``, ``proxies``): no local node publishes, subscribes or serves their topic."""
    local = frozenset(local)
    subs = {r.topic for r in local if r.kind == "sub"}
    pubs = {r.topic for r in local if r.kind == "pub"}
    return {"inlets": frozenset(t for t in wanted.inlets if t not in subs),
            "outlets": frozenset(t for t in wanted.outlets if t not in pubs),
            "proxies": wanted.proxies}


def limit_remote(wanted: Plan, local: Iterable[Resource],
                 first_heard: Mapping[Topic, float], cap: int) -> Tuple[Plan, int]:
    """``wanted`` with at most ``cap`` bridges that exist for remote beacons alone, those
    first heard kept (then by name); and how many were left out."""
    only = remote_only(wanted, local)
    ranked = sorted(((first_heard.get(t, float("inf")), t, kind)
                     for kind, topics in only.items() for t in topics))
    if len(ranked) <= cap:
        return wanted, 0
    dropped: Dict[str, Set[Topic]] = {"inlets": set(), "outlets": set(), "proxies": set()}
    for _first, topic, kind in ranked[max(0, cap):]:
        dropped[kind].add(topic)
    limited = Plan(declare=wanted.declare, outlets=wanted.outlets - dropped["outlets"],
                   inlets=wanted.inlets - dropped["inlets"], queryables=wanted.queryables,
                   proxies=wanted.proxies - dropped["proxies"], conflicts=wanted.conflicts)
    return limited, len(ranked) - max(0, cap)
