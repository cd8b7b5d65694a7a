"""The local ROS graph as the bridge sees it: other nodes' publishers, subscribers and services,
each with its type and md5sum.

The master knows names and types, not md5sums, definitions or latching. Like
zenoh-bridge-ros1 (``resource_cache.rs``), the bridge asks each publisher once: requestTopic,
then a TCPROS handshake with md5sum ``*`` whose answer header carries ``type``, ``md5sum``,
``message_definition`` and ``latching``; the connection is closed before any message. A
service answers a ``probe=1`` header with its type and md5sum (as rosservice asks). A
subscriber's md5sum comes from the installed definition of its type, or from a publisher of
that type here or remote; a subscriber whose type has neither is reported once and waits.

Answers are kept per (topic, node URI) and (service, URI) until they leave the graph; a node
that cannot be asked is asked again after a back-off. One ``LocalGraph`` is read by one thread.
"""

from __future__ import annotations

import socket
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Callable, Dict, FrozenSet, Iterable, List, Optional, Tuple

from minros.tools.master import Master
from minros.tools.services import probe_service
from minros.wire import sockets, tcpros
from minros.wire.rosapi import RemoteError
from minros.wire.slaveapi import SlaveClient
from minros.zenoh.keys import KeyMappingError, Resource, data_key

__all__ = ["LocalGraph", "PublisherInfo", "Snapshot", "probe_publisher"]

PROBE_TIMEOUT = 2.0
#: a publisher's answer is a handful of fields and its definition
MAX_HEADER = 1 << 20
RETRY_FIRST = 0.5
RETRY_MAX = 10.0
#: node URIs are looked up again this often (seconds)
NODE_URI_TTL = 2.0


@dataclass(frozen=True)
class PublisherInfo:
    type: str
    md5sum: str
    definition: str
    latching: bool


@dataclass(frozen=True)
class Snapshot:
    """One reading of the local graph."""

    resources: FrozenSet[Resource]
    #: (name, type, md5) of a local publisher -> what its publisher answered
    publishers: Dict[Tuple[str, str, str], PublisherInfo]


def probe_publisher(node_uri: str, topic: str, caller_id: str,
                    timeout: float = PROBE_TIMEOUT) -> Dict[str, str]:
    """The connection header the publisher of ``topic`` at ``node_uri`` answers with.
    OSError or tcpros.HeaderError when it cannot be asked or refuses."""
    try:
        with SlaveClient(node_uri, caller_id, timeout) as node:
            params = node.request_topic(topic, [["TCPROS"]])
    except RemoteError as exc:
        raise OSError(f"requestTopic of {topic} at {node_uri}: {exc}") from None
    if not isinstance(params, list) or len(params) != 3 or params[0] != "TCPROS":
        raise OSError(f"requestTopic of {topic} at {node_uri}: {params}")
    sock = socket.create_connection((params[1], int(params[2])), timeout=timeout)
    try:
        sock.sendall(tcpros.encode_header({"topic": topic, "md5sum": "*", "type": "*",
                                           "callerid": caller_id, "tcp_nodelay": "0"}))
        header = sockets.read_header(sock, MAX_HEADER)
    finally:
        sockets.close(sock)
    if "error" in header:
        raise OSError(f"publisher of {topic} at {node_uri} refused: {header['error']}")
    return header


def installed_md5(type_name: str) -> Optional[Tuple[str, str]]:
    """(md5sum, full definition) of an installed message type, or None."""
    from minros.msgs import get_message_class

    try:
        cls = get_message_class(type_name)
    except Exception:  # noqa: BLE001 - unknown, or a broken .msg: either way not installed
        return None
    return cls._md5sum, cls._full_text


def installed_service_md5(type_name: str) -> Optional[str]:
    from minros.msgs import get_service_class

    try:
        return get_service_class(type_name)._md5sum
    except Exception:  # noqa: BLE001
        return None


class _Answer:
    """A probe's result, or when to ask again."""

    __slots__ = ("value", "retry_at", "backoff")

    def __init__(self) -> None:
        self.value: Optional[Tuple] = None
        self.retry_at = 0.0
        self.backoff = RETRY_FIRST


class LocalGraph:
    """Reads the master of ``master_uri`` as node ``caller_id`` (whose own resources are left
    out); ``report(text)`` takes the lines worth a user's attention (called once per fault)."""

    def __init__(self, caller_id: str, master_uri: str, report: Callable[[str], None],
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.caller_id = caller_id
        self.master = Master(caller_id, master_uri, timeout=PROBE_TIMEOUT)
        self.report = report
        self.clock = clock
        self._pubs: Dict[Tuple[str, str], _Answer] = {}
        self._srvs: Dict[Tuple[str, str], _Answer] = {}
        self._node_uris: Dict[str, str] = {}
        self._uris_read = clock()
        self._installed: Dict[str, Optional[Tuple[str, str]]] = {}
        self._pool = ThreadPoolExecutor(max_workers=4, thread_name_prefix="minros-zenoh-probe")

    def close(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)
        self.master.close()

    # -- reading -------------------------------------------------------------------------

    def read(self, remote: Iterable[Resource] = ()) -> Snapshot:
        """The graph now. MasterIOError (an OSError) when the master cannot be reached."""
        pubs, subs, srvs = self.master.system_state()
        types = {t: ty for t, ty in self.master.topic_types()}
        me = self.caller_id
        now = self.clock()
        pub_pairs = [(t, n) for t, nodes in pubs for n in nodes if n != me]
        srv_pairs = [(s, n) for s, nodes in srvs for n in nodes if n != me]
        if now - self._uris_read >= NODE_URI_TTL:  # a node restarted under its name moves
            self._node_uris.clear()
            self._uris_read = now
        for node in {n for _t, n in pub_pairs}:
            self._lookup_node(node)
        self._forget(self._pubs, {(t, self._node_uris.get(n, "")) for t, n in pub_pairs})
        self._probe_publishers(pub_pairs, now)
        self._probe_services(srv_pairs, now)

        resources = set()
        publishers: Dict[Tuple[str, str, str], PublisherInfo] = {}
        known_md5: Dict[str, str] = {}
        for topic, node in pub_pairs:
            answer = self._pubs.get((topic, self._node_uris.get(node, "")))
            if answer is None or answer.value is None:
                continue
            info: PublisherInfo = answer.value[0]
            if not self._mappable(topic, info.type, info.md5sum):
                continue
            resources.add(Resource("pub", topic, info.type, info.md5sum))
            publishers.setdefault((topic, info.type, info.md5sum), info)
            known_md5.setdefault(info.type, info.md5sum)
        for r in remote:
            if r.kind in ("pub", "sub"):
                known_md5.setdefault(r.type, r.md5sum)
        for topic, nodes in subs:
            if not any(n != me for n in nodes):
                continue
            type_name = types.get(topic)
            if not type_name or type_name == "*":
                continue
            md5 = self._installed_md5(type_name) or known_md5.get(type_name)
            if md5 is None:
                self.report(f"subscriber-only topic {topic} ({type_name}) is not bridged yet: its "
                            "definition is not installed here and no publisher of it is known")
                continue
            if self._mappable(topic, type_name, md5):
                resources.add(Resource("sub", topic, type_name, md5))
        for service, node in srv_pairs:
            answer = self._srvs.get((service, node))
            if answer is not None and answer.value is not None:
                type_name, md5 = answer.value
                if self._mappable(service, type_name, md5):
                    resources.add(Resource("srv", service, type_name, md5))
        return Snapshot(frozenset(resources), publishers)

    def _mappable(self, name: str, type_name: str, md5: str) -> bool:
        try:
            data_key(name, type_name, md5)
            return True
        except KeyMappingError as exc:
            self.report(f"{name} is not bridged: {exc}")
            return False

    def _installed_md5(self, type_name: str) -> Optional[str]:
        if type_name not in self._installed:
            self._installed[type_name] = installed_md5(type_name)
        found = self._installed[type_name]
        return found[0] if found else None

    def installed_definition(self, type_name: str, md5: str) -> str:
        """The installed full definition of ``type_name`` if its md5sum is ``md5``, else ''."""
        if type_name not in self._installed:
            self._installed[type_name] = installed_md5(type_name)
        found = self._installed[type_name]
        return found[1] if found and found[0] == md5 else ""

    @staticmethod
    def _forget(answers: Dict, keep: set) -> None:
        for key in [k for k in answers if k not in keep]:
            del answers[key]

    # -- probes --------------------------------------------------------------------------

    def _lookup_node(self, node: str) -> Optional[str]:
        uri = self._node_uris.get(node)
        if uri is None:
            try:
                uri = self.master.lookupNode(node)
            except Exception:  # noqa: BLE001 - gone meanwhile: the next reading tells
                return None
            self._node_uris[node] = uri
        return uri

    def _probe_publishers(self, pairs: List[Tuple[str, str]], now: float) -> None:
        jobs = []
        for topic, node in pairs:
            uri = self._lookup_node(node)
            if uri is None:
                continue
            answer = self._pubs.setdefault((topic, uri), _Answer())
            if answer.value is None and answer.retry_at <= now:
                jobs.append((topic, node, uri, answer,
                             self._pool.submit(probe_publisher, uri, topic, self.caller_id)))
        for topic, node, _uri, answer, job in jobs:
            try:
                header = job.result(timeout=PROBE_TIMEOUT * 3)
                info = PublisherInfo(header.get("type", ""), header.get("md5sum", ""),
                                     header.get("message_definition", ""),
                                     header.get("latching", "0") == "1")
                answer.value = (info,)
            except Exception as exc:  # noqa: BLE001 - any failure: ask again later
                answer.retry_at = now + answer.backoff
                answer.backoff = min(RETRY_MAX, answer.backoff * 2)
                self._node_uris.pop(node, None)  # the node may have restarted elsewhere
                if answer.backoff >= RETRY_MAX:
                    self.report(f"cannot ask the publisher {node} of {topic} for its type: {exc}")

    def _probe_services(self, pairs: List[Tuple[str, str]], now: float) -> None:
        jobs = []
        self._forget(self._srvs, set(pairs))
        for pair in pairs:
            answer = self._srvs.setdefault(pair, _Answer())
            if answer.value is not None or answer.retry_at > now:
                continue
            try:  # once per (service, provider): not a lookup per service per reading
                uri = self.master.lookupService(pair[0])
            except Exception:  # noqa: BLE001 - gone meanwhile: the next reading tells
                continue
            jobs.append((pair[0], answer, self._pool.submit(
                probe_service, uri, pair[0], self.caller_id, PROBE_TIMEOUT)))
        for service, answer, job in jobs:
            try:
                header = job.result(timeout=PROBE_TIMEOUT * 3)
                if "error" in header:
                    raise OSError(header["error"])
                answer.value = (header.get("type", ""), header.get("md5sum", ""))
            except Exception as exc:  # noqa: BLE001
                answer.retry_at = now + answer.backoff
                answer.backoff = min(RETRY_MAX, answer.backoff * 2)
                if answer.backoff >= RETRY_MAX:
                    self.report(f"cannot ask the service {service} for its type: {exc}")
