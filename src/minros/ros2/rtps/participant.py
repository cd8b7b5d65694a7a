"""The DDS participant: the thin I/O layer that runs the sans-IO parts on UDP sockets.

One :class:`Participant` per domain and process (rmw's model: a ROS 2 context is one DDS
participant, its nodes share it). It owns:

* three UDP sockets, all on the loopback interface unless another host is named: the SPDP
  multicast group (239.255.0.1, port 7400 + 250 * domain), the metatraffic unicast port and
  the user-data unicast port of its participant id (the first id whose two ports are free,
  as Fast DDS and Cyclone choose theirs: 7410 + 2 * id and 7411 + 2 * id in domain 0);
* discovery: SPDP announcements (five at start 0.1 s apart, then every ``announce_period``)
  to the multicast group and to the unicast ports of the first ``localhost_peers``
  participant ids on localhost, for peers that discover by unicast only
  (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` makes Fast DDS do that); SEDP's built-in
  writers and readers (reliable, transient-local) for publications and subscriptions;
  leases (a peer silent for its lease is dropped, with one log line);
* the local writers and readers (:class:`LocalWriter`, :class:`LocalReader`), matched with
  remote ones by topic, type name and QoS, and with each other in-process.

**Threads**: ``minros-rtps-meta`` reads the two discovery sockets, ``minros-rtps-user`` the
user-data socket, ``minros-rtps-timer`` sends announcements and heartbeats and expires
leases. A reader's callback runs in ``minros-rtps-user`` (or in the writing thread, for an
in-process match): it should hand long work elsewhere. A publishing thread sends its own
datagrams (``sendmsg`` of the payload's memoryview slices: no copy of a big payload).

**Locks**: ``Participant._lock`` guards the discovery tables and is taken before an
endpoint's own lock (``LocalEndpoint.lock``, guarding its state machine), never after.
Nothing is sent and no callback runs with either held.
"""

from __future__ import annotations

import errno
import logging
import os
import select
import selectors
import socket
import threading
import time
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Set, Tuple

from minros.ros2.rtps import discovery as d
from minros.ros2.rtps import guid as g
from minros.ros2.rtps import messages as m
from minros.ros2.rtps import params as p
from minros.ros2.rtps.discovery import EndpointData, ParticipantData, Qos
from minros.ros2.rtps.endpoint import Address, Datagram, Sample
from minros.ros2.rtps.params import Locator
from minros.ros2.rtps.reader import Reader
from minros.ros2.rtps.writer import Writer

__all__ = ["LocalReader", "LocalWriter", "Participant", "RemoteParticipant"]

log = logging.getLogger("minros.ros2")

#: the socket buffer minros asks for (the kernel caps it at net.core.rmem_max / wmem_max)
SOCKET_BUFFER = 8 << 20
#: participant ids tried when choosing ours (RTPS leaves 120 per domain)
MAX_PARTICIPANT_ID = 120

Listener = Callable[[str, object], None]

#: bytes of fragments sent to a reader in one go at first, by its vendor (what its socket
#: holds: Fast DDS keeps the OS's default, 212992 bytes on Linux; Cyclone asks for 1 MiB;
#: minros for 8 MiB); the writer adapts from there (``writer``'s flow control)
FIRST_BURST = {g.VENDOR_FASTDDS: 3 * 64_000, g.VENDOR_CYCLONE: 8 * 64_000,
               g.VENDOR_MINROS: 16 * 64_000}
#: a minros reader answers each burst at once: at most this much goes unanswered to it (its
#: socket holds 8 MiB; a reader behind is waited for, not overflowed)
MINROS_UNANSWERED = 2 << 20
#: how long a writer that paces in its caller's thread sends bursts there (the timer thread
#: sends what is left after)
PACE_IN_CALLER_LIMIT = 0.05


class RemoteParticipant:
    """A participant discovered by SPDP."""

    __slots__ = ("data", "last_seen", "meta_addresses", "user_addresses", "first_seen")

    def __init__(self, data: ParticipantData, now: float) -> None:
        self.data = data
        self.first_seen = now
        self.last_seen = now
        self.meta_addresses: List[Address] = []
        self.user_addresses: List[Address] = []

    @property
    def prefix(self) -> bytes:
        return self.data.prefix

    @property
    def vendor(self) -> bytes:
        return self.data.vendor

    @property
    def enclave(self) -> Optional[str]:
        return d.user_data_value(self.data.user_data, "enclave")

    def describe(self) -> str:
        return f"{g.guid_text(self.prefix)} ({g.vendor_name(self.vendor)})"


class LocalEndpoint:
    """A writer or reader of this participant: its SEDP data and matches."""

    def __init__(self, participant: Participant, data: EndpointData) -> None:
        self.participant = participant
        self.data = data
        self.guid = data.guid
        self.lock = threading.Lock()
        self.changed = threading.Condition(self.lock)
        #: matched remote (or local) endpoints, by GUID
        self.matched: Dict[bytes, EndpointData] = {}
        #: endpoints of this topic that do not match, and why
        self.incompatible: Dict[bytes, str] = {}
        self.closed = False

    @property
    def topic(self) -> str:
        return self.data.topic

    def matched_count(self) -> int:
        with self.lock:
            return len(self.matched)

    def wait_matched(self, guid: bytes, timeout: float) -> bool:
        """Wait until endpoint ``guid`` matched this one (False on timeout or close)."""
        deadline = time.monotonic() + timeout
        with self.lock:
            while guid not in self.matched and not self.closed:
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self.changed.wait(left)
            return guid in self.matched


class LocalWriter(LocalEndpoint):
    def __init__(self, participant: Participant, data: EndpointData, machine: Writer) -> None:
        super().__init__(participant, data)
        self.machine = machine
        #: in-process readers matched to this writer
        self.local_readers: List[LocalReader] = []
        #: write() sends a fragmented sample's later bursts itself, sleeping between them,
        #: instead of leaving them to the timer thread: the caller waits up to
        #: PACE_IN_CALLER_LIMIT, and the bursts leave on time in a process whose other
        #: threads hold the GIL for milliseconds (the bridge's, converting 6 MB images)
        self.pace_in_caller = False

    def write(self, payload: bytes | bytearray | memoryview, *, inline_qos: bytes = b"",
              timestamp: Optional[int] = None) -> int:
        """Publish one serialized sample (its 4-byte encapsulation header first). Returns its
        sequence number. A KEEP_ALL writer whose readers lag waits up to the reliability's
        max_blocking_time for room."""
        part = self.participant
        now = time.monotonic()
        stamp = time.time_ns() if timestamp is None else timestamp
        with self.lock:
            if self.closed:
                raise RuntimeError(f"the writer of {self.topic} is closed")
            machine = self.machine
            if machine.keep_all and machine.full():
                deadline = now + self.data.qos.max_blocking_time
                while machine.full() and not self.closed:
                    left = deadline - time.monotonic()
                    if left <= 0 or not self.changed.wait(left):
                        break
                now = time.monotonic()
            sn, out = machine.write(payload, now, inline_qos=inline_qos, timestamp=stamp)
            due = machine.next_deadline()
            local = list(self.local_readers)
        part._send(out)
        if due is not None and self.pace_in_caller:
            due = self._pace(due)
        if due is not None:
            part._wake_timer(due)
        if local:
            sample = Sample(self.guid, sn, bytes(payload), stamp, inline_qos[:-4] or None)
            for reader in local:
                reader._deliver_local(sample)
        return sn

    def _pace(self, due: Optional[float]) -> Optional[float]:
        """Send the bursts of a fragmented sample from the writing thread, each when it is
        due (``pace_in_caller``), for at most PACE_IN_CALLER_LIMIT; the next deadline."""
        part = self.participant
        limit = time.monotonic() + PACE_IN_CALLER_LIMIT
        while due is not None:
            machine = self.machine
            if not any(p.paced and not p.awaiting for p in machine.proxies.values()):
                break
            now = time.monotonic()
            if now > limit:
                break
            if due > now:
                time.sleep(due - now)
            with self.lock:
                now = time.monotonic()
                out = machine.tick(now)
                due = machine.next_deadline()
            part._send(out)
        return due

    def wait_acknowledged(self, sn: int, timeout: float) -> bool:
        """Wait until every reliable reader acknowledged ``sn``."""
        deadline = time.monotonic() + timeout
        with self.lock:
            while not self.machine.acknowledged(sn):
                left = deadline - time.monotonic()
                if left <= 0 or self.closed:
                    return False
                self.changed.wait(left)
            return True


class LocalReader(LocalEndpoint):
    def __init__(self, participant: Participant, data: EndpointData, machine: Reader,
                 callback: Callable[[Sample], None], ignore_local: bool) -> None:
        super().__init__(participant, data)
        self.machine = machine
        self.callback = callback
        self.ignore_local = ignore_local
        self._local_last: Dict[bytes, int] = {}

    def _deliver(self, samples: List[Sample]) -> None:
        for sample in samples:
            try:
                self.callback(sample)
            except Exception:  # a callback's bug must not stop the receive thread
                log.exception("ROS 2 callback of %s failed", self.topic)

    def _deliver_local(self, sample: Sample) -> None:
        self._deliver([sample])


class Participant:
    """A DDS domain participant on UDP (see the module docstring)."""

    def __init__(self, domain_id: int = 0, *, host: str = "127.0.0.1",
                 participant_id: Optional[int] = None, lease_duration: float = 20.0,
                 announce_period: float = 3.0, localhost_peers: int = 32,
                 user_data: bytes = b"", multicast: bool = True) -> None:
        if not 0 <= domain_id <= 232:
            raise ValueError(f"domain id {domain_id}: DDS domains are 0..232")
        self.domain_id = domain_id
        self.host = host
        self.loopback = host.startswith("127.")
        self.prefix = g.new_prefix()
        self.guid = self.prefix + g.ENTITYID_PARTICIPANT
        self.header = m.header(self.prefix)
        self.lease_duration = lease_duration
        self.announce_period = announce_period
        self.localhost_peers = localhost_peers
        self.user_data = user_data
        self.multicast = multicast
        self._requested_id = participant_id
        self.participant_id = -1
        self._lock = threading.RLock()
        self._remotes: Dict[bytes, RemoteParticipant] = {}
        self._remote_endpoints: Dict[bytes, EndpointData] = {}
        self._writers: Dict[bytes, LocalWriter] = {}  # by entity id
        self._readers: Dict[bytes, LocalReader] = {}
        self._readers_by_writer: Dict[bytes, List[LocalReader]] = {}
        self._sedp_sn: Dict[bytes, int] = {}  # local endpoint GUID -> its SEDP change
        self._listeners: List[Listener] = []
        self._reported: Set[Tuple[bytes, bytes]] = set()
        self._bad_input: Dict[str, float] = {}
        self._next_key = 0x10
        self._closed = False
        self._started = False
        self._timer_event = threading.Event()
        self._timer_target = 0.0
        self._threads: List[threading.Thread] = []
        self._announce_left = 5
        self._next_announce = 0.0
        self._next_lease_check = 0.0
        self.socket_buffer = 0

    # -- lifecycle ---------------------------------------------------------------------------

    def start(self) -> Participant:
        """Bind the sockets, start the threads, announce."""
        self._bind()
        self.spdp_data = ParticipantData(
            prefix=self.prefix, domain_id=self.domain_id, lease_duration=self.lease_duration,
            metatraffic_unicast=[Locator.udpv4(self.host, self.meta_port)],
            metatraffic_multicast=[Locator.udpv4(d.SPDP_MULTICAST_GROUP, self.mc_port)]
            if self.multicast else [],
            default_unicast=[Locator.udpv4(self.host, self.user_port)],
            user_data=self.user_data)
        self._spdp_payload = d.encode_participant(self.spdp_data)
        # SEDP: built-in, reliable, transient-local, keyed
        for wid, rid in ((g.SEDP_PUBLICATIONS_WRITER, g.SEDP_PUBLICATIONS_READER),
                         (g.SEDP_SUBSCRIPTIONS_WRITER, g.SEDP_SUBSCRIPTIONS_READER)):
            wdata = EndpointData(self.prefix + wid, "DCPS", "builtin")
            writer = LocalWriter(self, wdata, Writer(
                wdata.guid, self.header, reliable=True, transient_local=True, keep_all=True,
                depth=1 << 30, max_samples=1 << 30, heartbeat_period=0.2))
            self._writers[wid] = writer
            rdata = EndpointData(self.prefix + rid, "DCPS", "builtin")
            reader = LocalReader(self, rdata, Reader(rdata.guid, self.header, reliable=True,
                                                     durable=True),
                                 self._on_sedp_sample, ignore_local=True)
            self._readers[rid] = reader
        self._wake_r, self._wake_w = os.pipe()
        self._started = True
        for name, target in (("minros-rtps-meta", self._receive_meta),
                             ("minros-rtps-user", self._receive_user),
                             ("minros-rtps-timer", self._timer)):
            t = threading.Thread(target=target, name=name, daemon=True)
            t.start()
            self._threads.append(t)
        return self

    def _bind(self) -> None:
        ids = ([self._requested_id] if self._requested_id is not None
               else range(MAX_PARTICIPANT_ID))
        for pid in ids:
            meta = _udp_socket()
            user = _udp_socket()
            try:
                meta.bind((self.host, d.metatraffic_unicast_port(self.domain_id, pid)))
                user.bind((self.host, d.user_unicast_port(self.domain_id, pid)))
            except OSError as exc:
                meta.close()
                user.close()
                if exc.errno != errno.EADDRINUSE or self._requested_id is not None:
                    raise
                continue
            self.participant_id = pid
            self.meta_sock, self.user_sock = meta, user
            break
        else:
            raise OSError(errno.EADDRINUSE, f"no free participant id in domain "
                          f"{self.domain_id}: ports from "
                          f"{d.metatraffic_unicast_port(self.domain_id, 0)} are all taken")
        self.meta_port = d.metatraffic_unicast_port(self.domain_id, self.participant_id)
        self.user_port = d.user_unicast_port(self.domain_id, self.participant_id)
        self.mc_port = d.metatraffic_multicast_port(self.domain_id)
        self.socket_buffer = _grow_buffers(self.user_sock)
        _grow_buffers(self.meta_sock)
        send = self.user_sock
        # multicast leaves by the named interface (loopback by default), one hop at most
        send.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(self.host))
        send.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
        send.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        self.mc_sock: Optional[socket.socket] = None
        if self.multicast and not _multicast_capable(self.host):
            # a host's lo has no MULTICAST flag: the group would be sent to and never heard
            log.info("ROS 2: the interface of %s does not do multicast; discovering by "
                     "unicast to the participant ports of localhost (as Fast DDS does with "
                     "ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST)", self.host)
        elif self.multicast:
            mc = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            mc.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if hasattr(socket, "SO_REUSEPORT"):
                mc.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
            try:
                mc.bind((d.SPDP_MULTICAST_GROUP, self.mc_port))
                mc.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                              socket.inet_aton(d.SPDP_MULTICAST_GROUP)
                              + socket.inet_aton(self.host))
                _grow_buffers(mc)
                self.mc_sock = mc
            except OSError as exc:
                mc.close()
                log.info("ROS 2: no multicast discovery on %s (%s); discovering by unicast "
                         "to localhost's participant ports", self.host, exc.strerror)
        self._send_sock = send

    def close(self) -> None:
        """Tell the peers this participant is leaving, stop the threads, close the sockets."""
        if self._closed:
            return
        self._closed = True
        if self._started:
            try:
                self._send(self._spdp_datagrams(dispose=True))
            except OSError:
                pass
            os.write(self._wake_w, b"x")
            self._timer_event.set()
            for t in self._threads:
                if t is not threading.current_thread():
                    t.join(timeout=2)
            for sock in (self.meta_sock, self.user_sock, self.mc_sock):
                if sock is not None:
                    sock.close()
            os.close(self._wake_r)
            os.close(self._wake_w)
        for ep in [*self._writers.values(), *self._readers.values()]:
            with ep.lock:
                ep.closed = True
                ep.changed.notify_all()

    def __enter__(self) -> Participant:
        return self.start() if not self._started else self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- listeners and queries ---------------------------------------------------------------

    def add_listener(self, listener: Listener) -> None:
        """``listener(event, obj)`` is called (from a participant thread, no lock held) on
        "participant+"/"participant-" (a RemoteParticipant), "endpoint+"/"endpoint-" (an
        EndpointData), "matched"/"unmatched" ((LocalEndpoint, guid)) and "incompatible"
        ((LocalEndpoint, EndpointData, reason))."""
        with self._lock:
            self._listeners.append(listener)

    def _notify(self, events: List[Tuple[str, object]]) -> None:
        if not events:
            return
        with self._lock:
            listeners = list(self._listeners)
        for event, obj in events:
            for listener in listeners:
                try:
                    listener(event, obj)
                except Exception:
                    log.exception("ROS 2 discovery listener failed on %s", event)

    def participants(self) -> List[RemoteParticipant]:
        with self._lock:
            return list(self._remotes.values())

    def remote_endpoints(self) -> List[EndpointData]:
        with self._lock:
            return list(self._remote_endpoints.values())

    def local_endpoints(self) -> List[LocalEndpoint]:
        with self._lock:
            return [ep for ep in [*self._writers.values(), *self._readers.values()]
                    if ep.data.topic != "DCPS"]

    def remote(self, prefix: bytes) -> Optional[RemoteParticipant]:
        with self._lock:
            return self._remotes.get(prefix)

    # -- endpoints ---------------------------------------------------------------------------

    def _new_entity(self, kind: int) -> bytes:
        with self._lock:
            self._next_key += 1
            return g.entity_id(self._next_key, kind)

    def create_writer(self, topic: str, type_name: str, qos: Qos, *, user_data: bytes = b"",
                      keyed: bool = False, **tuning: Any) -> LocalWriter:
        """A writer of ``topic``; ``tuning`` passes Writer's flow-control settings."""
        entity = self._new_entity(g.KIND_WRITER_WITH_KEY if keyed else g.KIND_WRITER_NO_KEY)
        data = EndpointData(self.prefix + entity, topic, type_name, qos,
                            unicast=[Locator.udpv4(self.host, self.user_port)],
                            user_data=user_data, vendor=g.VENDOR_MINROS)
        machine = Writer(data.guid, self.header, reliable=qos.reliability == d.RELIABLE,
                         transient_local=qos.durability >= d.TRANSIENT_LOCAL,
                         keep_all=qos.history == d.KEEP_ALL, depth=qos.depth, **tuning)
        writer = LocalWriter(self, data, machine)
        with self._lock:
            self._writers[entity] = writer
        self._announce_endpoint(writer)
        self._match_new_local(writer)
        return writer

    def create_reader(self, topic: str, type_name: str, qos: Qos,
                      callback: Callable[[Sample], None], *, user_data: bytes = b"",
                      keyed: bool = False, ignore_local: bool = False) -> LocalReader:
        """A reader of ``topic``; ``callback(sample)`` runs for every sample, in order."""
        entity = self._new_entity(g.KIND_READER_WITH_KEY if keyed else g.KIND_READER_NO_KEY)
        data = EndpointData(self.prefix + entity, topic, type_name, qos,
                            unicast=[Locator.udpv4(self.host, self.user_port)],
                            user_data=user_data, vendor=g.VENDOR_MINROS)
        machine = Reader(data.guid, self.header, reliable=qos.reliability == d.RELIABLE,
                         durable=qos.durability >= d.TRANSIENT_LOCAL)
        reader = LocalReader(self, data, machine, callback, ignore_local)
        with self._lock:
            self._readers[entity] = reader
        self._announce_endpoint(reader)
        self._match_new_local(reader)
        return reader

    def delete(self, endpoint: LocalEndpoint) -> None:
        """Remove a local writer or reader: unmatched everywhere, disposed in SEDP."""
        entity = endpoint.guid[12:]
        events: List[Tuple[str, object]] = []
        with self._lock:
            table = self._writers if isinstance(endpoint, LocalWriter) else self._readers
            if table.get(entity) is not endpoint:
                return
            del table[entity]
            for other in list(endpoint.matched):
                self._unmatch(endpoint, other, events)
            for ep in [*self._writers.values(), *self._readers.values()]:
                if endpoint.guid in ep.matched:
                    self._unmatch(ep, endpoint.guid, events)
        with endpoint.lock:
            endpoint.closed = True
            endpoint.changed.notify_all()
        self._dispose_endpoint(endpoint)
        self._notify(events)

    # -- SEDP: our endpoints -----------------------------------------------------------------

    def _sedp_writer(self, endpoint: LocalEndpoint) -> LocalWriter:
        wid = (g.SEDP_PUBLICATIONS_WRITER if isinstance(endpoint, LocalWriter)
               else g.SEDP_SUBSCRIPTIONS_WRITER)
        return self._writers[wid]

    def _announce_endpoint(self, endpoint: LocalEndpoint) -> None:
        sedp = self._sedp_writer(endpoint)
        payload = d.encode_endpoint(endpoint.data, self.guid)
        now = time.monotonic()
        with sedp.lock:
            old = self._sedp_sn.get(endpoint.guid)
            if old is not None:
                sedp.machine.remove_change(old)
            sn, out = sedp.machine.write(payload, now, timestamp=time.time_ns())
            self._sedp_sn[endpoint.guid] = sn
            due = sedp.machine.next_deadline()
        self._send(out)
        if due is not None:
            self._wake_timer(due)

    def _dispose_endpoint(self, endpoint: LocalEndpoint) -> None:
        sedp = self._sedp_writer(endpoint)
        qos = (p.ParamWriter().add(p.PID_KEY_HASH, endpoint.guid)
               .add(p.PID_STATUS_INFO, b"\0\0\0\x03").encode())
        key = d.key_payload(p.PID_ENDPOINT_GUID, endpoint.guid)
        with sedp.lock:
            old = self._sedp_sn.pop(endpoint.guid, None)
            if old is not None:
                sedp.machine.remove_change(old)
            _, out = sedp.machine.write(key, time.monotonic(), inline_qos=qos,
                                        timestamp=time.time_ns(), key=True)
        self._send(out)

    # -- matching ----------------------------------------------------------------------------

    def _match_new_local(self, endpoint: LocalEndpoint) -> None:
        events: List[Tuple[str, object]] = []
        with self._lock:
            for remote in list(self._remote_endpoints.values()):
                self._try_match(endpoint, remote, events)
            # in-process: this participant's other endpoints of the topic
            others = self._readers if isinstance(endpoint, LocalWriter) else self._writers
            for other in list(others.values()):
                if other.data.topic == endpoint.data.topic and other is not endpoint:
                    writer, reader = ((endpoint, other) if isinstance(endpoint, LocalWriter)
                                      else (other, endpoint))
                    self._match_local(writer, reader, events)  # type: ignore[arg-type]
        self._notify(events)

    def _match_local(self, writer: LocalWriter, reader: LocalReader,
                     events: List[Tuple[str, object]]) -> None:
        if reader.ignore_local or writer.data.type_name != reader.data.type_name:
            return
        if d.incompatibility(writer.data.qos, reader.data.qos) is not None:
            return
        with writer.lock:
            writer.local_readers.append(reader)
            writer.matched[reader.guid] = reader.data
            writer.changed.notify_all()
        with reader.lock:
            reader.matched[writer.guid] = writer.data
            reader.changed.notify_all()
        events.append(("matched", (writer, reader.guid)))
        events.append(("matched", (reader, writer.guid)))

    def _try_match(self, local: LocalEndpoint, remote: EndpointData,
                   events: List[Tuple[str, object]]) -> None:
        """Match ``local`` with ``remote`` if they are opposite ends of one topic and their
        QoS allow it (the participant lock is held)."""
        if remote.topic != local.data.topic or remote.is_reader == isinstance(local, LocalReader):
            return
        if remote.guid in local.matched:
            return
        pair = (local.guid, remote.guid)
        if remote.type_name != local.data.type_name:
            if pair not in self._reported:
                self._reported.add(pair)
                log.warning("ROS 2 topic %s: type %s here, %s at %s: not matched",
                            remote.topic, local.data.type_name, remote.type_name,
                            self._describe_remote(remote))
            return
        if isinstance(local, LocalWriter):
            reason = d.incompatibility(local.data.qos, remote.qos)
            writer_qos, reader_qos = local.data.qos, remote.qos
        else:
            reason = d.incompatibility(remote.qos, local.data.qos)
            writer_qos, reader_qos = remote.qos, local.data.qos
        if reason is not None:
            local.incompatible[remote.guid] = reason
            if pair not in self._reported:
                self._reported.add(pair)
                where = self._describe_remote(remote)
                log.warning("ROS 2 topic %s: QoS cannot match (%s): writer %s [%s], reader %s "
                            "[%s]", remote.topic, reason,
                            "here" if isinstance(local, LocalWriter) else where,
                            writer_qos.describe(),
                            where if isinstance(local, LocalWriter) else "here",
                            reader_qos.describe())
            events.append(("incompatible", (local, remote, reason)))
            return
        participant = self._remotes.get(remote.participant_prefix)
        addresses = self._addresses(remote.unicast) or (
            participant.user_addresses if participant is not None else [])
        if not addresses:
            if pair not in self._reported:
                self._reported.add(pair)
                log.warning("ROS 2 topic %s: %s announces no locator this participant can "
                            "reach (on %s)", remote.topic, self._describe_remote(remote),
                            self.host)
            return
        now = time.monotonic()
        vendor = participant.vendor if participant is not None else remote.vendor
        with local.lock:
            if isinstance(local, LocalWriter):
                out = local.machine.add_reader(
                    remote.guid, addresses, remote.qos.reliability == d.RELIABLE,
                    remote.qos.durability >= d.TRANSIENT_LOCAL, now,
                    burst=FIRST_BURST.get(vendor), answers_bursts=vendor == g.VENDOR_MINROS,
                    cap=MINROS_UNANSWERED if vendor == g.VENDOR_MINROS else None)
            else:
                assert isinstance(local, LocalReader)
                out = local.machine.add_writer(remote.guid, addresses, now)
                self._readers_by_writer.setdefault(remote.guid, []).append(local)
            local.matched[remote.guid] = remote
            local.incompatible.pop(remote.guid, None)
            local.changed.notify_all()
        self._send(out)
        self._wake_timer(now)
        events.append(("matched", (local, remote.guid)))

    def _unmatch(self, local: LocalEndpoint, other: bytes,
                 events: List[Tuple[str, object]]) -> None:
        with local.lock:
            if local.matched.pop(other, None) is None:
                local.incompatible.pop(other, None)
                return
            if isinstance(local, LocalWriter):
                local.machine.remove_reader(other)
                local.local_readers = [r for r in local.local_readers if r.guid != other]
            else:
                assert isinstance(local, LocalReader)
                local.machine.remove_writer(other)
                readers = self._readers_by_writer.get(other)
                if readers is not None:
                    readers[:] = [r for r in readers if r is not local]
                    if not readers:
                        del self._readers_by_writer[other]
            local.changed.notify_all()
        events.append(("unmatched", (local, other)))

    def _describe_remote(self, remote: EndpointData) -> str:
        participant = self._remotes.get(remote.participant_prefix)
        vendor = g.vendor_name(participant.vendor if participant else remote.vendor)
        return f"{g.guid_text(remote.guid)} ({vendor})"

    def _addresses(self, locators: Iterable[Locator]) -> List[Address]:
        """The UDPv4 locators this participant may send to: loopback ones only when it is on
        loopback (a peer's other addresses are never used)."""
        out: List[Address] = []
        for loc in locators:
            if loc.kind != p.LOCATOR_KIND_UDPV4 or not 0 < loc.port < 65536:
                continue
            host = loc.host
            if host == "0.0.0.0" or host.startswith("224.") or host.startswith("239."):
                continue
            if self.loopback and not host.startswith("127."):
                continue
            if (host, loc.port) not in out:
                out.append((host, loc.port))
        return out

    # -- SPDP --------------------------------------------------------------------------------

    def _spdp_datagrams(self, dispose: bool = False) -> List[Datagram]:
        if dispose:
            qos = (p.ParamWriter().add(p.PID_KEY_HASH, self.guid)
                   .add(p.PID_STATUS_INFO, b"\0\0\0\x03").encode())
            key = d.key_payload(p.PID_PARTICIPANT_GUID, self.guid)
            head, pad = m.data(g.ENTITYID_UNKNOWN, g.SPDP_WRITER, 2, len(key), qos, key=True)
            parts: List[object] = [self.header, m.info_ts(time.time_ns()), head, key, pad]
        else:
            payload = self._spdp_payload
            head, pad = m.data(g.SPDP_READER, g.SPDP_WRITER, 1, len(payload))
            parts = [self.header, m.info_ts(time.time_ns()), head, payload, pad]
        addresses: List[Address] = []
        if self.mc_sock is not None:
            addresses.append((d.SPDP_MULTICAST_GROUP, self.mc_port))
        if self.loopback:
            for pid in range(self.localhost_peers):
                if pid != self.participant_id:
                    addresses.append(("127.0.0.1",
                                      d.metatraffic_unicast_port(self.domain_id, pid)))
        with self._lock:
            for remote in self._remotes.values():
                for addr in remote.meta_addresses:
                    if addr not in addresses:
                        addresses.append(addr)
        return [Datagram(addresses, parts)]  # type: ignore[arg-type]

    def _on_spdp(self, sub: m.Data, now: float) -> None:
        little = bool(sub.flags & 1)
        if sub.payload is None or sub.key or p.status_info(
                bytes(sub.inline_qos) if sub.inline_qos is not None else None, little):
            self._remove_participant(sub.src, "left the domain")
            return
        try:
            data = d.decode_participant(sub.payload)
        except d.DiscoveryError as exc:
            self._report_bad(sub.src.hex(), f"SPDP data that does not decode: {exc}")
            return
        if data.prefix == self.prefix:
            return
        if data.domain_id is not None and data.domain_id != self.domain_id:
            return
        events: List[Tuple[str, object]] = []
        with self._lock:
            remote = self._remotes.get(data.prefix)
            new = remote is None
            if remote is None:
                remote = RemoteParticipant(data, now)
                self._remotes[data.prefix] = remote
            remote.data = data
            remote.last_seen = now
            remote.meta_addresses = self._addresses(data.metatraffic_unicast)
            remote.user_addresses = self._addresses(data.default_unicast)
            if new:
                self._match_builtin(remote, now)
                events.append(("participant+", remote))
        if new:
            log.debug("ROS 2 participant %s joined", remote.describe())
            # answer at once, so it need not wait for our next announcement
            dg = self._spdp_datagrams()[0]
            self._send([Datagram(remote.meta_addresses, dg.buffers)])
        self._notify(events)

    def _match_builtin(self, remote: RemoteParticipant, now: float) -> None:
        """SEDP with a new participant: our announcers to its detectors and back."""
        bits = remote.data.builtin_endpoints
        addresses = remote.meta_addresses
        if not addresses:
            return
        prefix = remote.prefix
        out: List[Datagram] = []
        pairs = ((d.PUBLICATIONS_DETECTOR, g.SEDP_PUBLICATIONS_WRITER, g.SEDP_PUBLICATIONS_READER),
                 (d.SUBSCRIPTIONS_DETECTOR, g.SEDP_SUBSCRIPTIONS_WRITER,
                  g.SEDP_SUBSCRIPTIONS_READER))
        for detector, wid, rid in pairs:
            if bits & detector:
                writer = self._writers[wid]
                with writer.lock:
                    out += writer.machine.add_reader(prefix + rid, addresses, True, True, now)
                    writer.matched[prefix + rid] = EndpointData(prefix + rid, "DCPS", "builtin")
        pairs = ((d.PUBLICATIONS_ANNOUNCER, g.SEDP_PUBLICATIONS_WRITER,
                  g.SEDP_PUBLICATIONS_READER),
                 (d.SUBSCRIPTIONS_ANNOUNCER, g.SEDP_SUBSCRIPTIONS_WRITER,
                  g.SEDP_SUBSCRIPTIONS_READER))
        for announcer, wid, rid in pairs:
            if bits & announcer:
                reader = self._readers[rid]
                with reader.lock:
                    out += reader.machine.add_writer(prefix + wid, addresses, now)
                    reader.matched[prefix + wid] = EndpointData(prefix + wid, "DCPS", "builtin")
                self._readers_by_writer.setdefault(prefix + wid, []).append(reader)
        self._send(out)
        self._wake_timer(now)

    def _remove_participant(self, prefix: bytes, why: str) -> None:
        events: List[Tuple[str, object]] = []
        with self._lock:
            remote = self._remotes.pop(prefix, None)
            if remote is None:
                return
            for guid in [gd for gd in self._remote_endpoints if gd[:12] == prefix]:
                self._remove_remote_endpoint(guid, events)
            for ep in [*self._writers.values(), *self._readers.values()]:
                for other in [o for o in ep.matched if o[:12] == prefix]:
                    self._unmatch(ep, other, events)
            self._reported = {pair for pair in self._reported if pair[1][:12] != prefix}
            events.append(("participant-", remote))
        enclave = remote.enclave
        log.info("ROS 2 participant %s%s %s", remote.describe(),
                 f" (enclave {enclave})" if enclave else "", why)
        self._notify(events)

    def _remove_remote_endpoint(self, guid: bytes, events: List[Tuple[str, object]]) -> None:
        data = self._remote_endpoints.pop(guid, None)
        if data is None:
            return
        for ep in [*self._writers.values(), *self._readers.values()]:
            if guid in ep.matched or guid in ep.incompatible:
                self._unmatch(ep, guid, events)
        events.append(("endpoint-", data))

    # -- SEDP: theirs ------------------------------------------------------------------------

    def _on_sedp_sample(self, sample: Sample) -> None:
        prefix = sample.writer[:12]
        status = p.status_info(sample.inline_qos, sample.little)
        events: List[Tuple[str, object]] = []
        if status:
            key = p.find(sample.inline_qos, sample.little, p.PID_KEY_HASH)
            guid = bytes(key[:16]) if key is not None and len(key) >= 16 else None
            if guid is None:
                try:
                    plist = p.parse_params(memoryview(sample.payload)[4:], True)
                    guid = next((bytes(v[:16]) for pid, v in plist
                                 if pid == p.PID_ENDPOINT_GUID), None)
                except p.ParamError:
                    guid = None
            if guid is not None and guid[:12] == prefix:
                with self._lock:
                    self._remove_remote_endpoint(guid, events)
            self._notify(events)
            return
        with self._lock:
            remote = self._remotes.get(prefix)
            vendor = remote.vendor if remote is not None else b""
        try:
            data = d.decode_endpoint(memoryview(sample.payload), vendor)
        except d.DiscoveryError as exc:
            self._report_bad(g.guid_text(sample.writer), f"SEDP data that does not decode: {exc}")
            return
        if data.guid[:12] != prefix:
            return
        with self._lock:
            old = self._remote_endpoints.get(data.guid)
            self._remote_endpoints[data.guid] = data
            if old is not None:
                for ep in [*self._writers.values(), *self._readers.values()]:
                    if data.guid in ep.matched:
                        ep.matched[data.guid] = data
            else:
                events.append(("endpoint+", data))
            for ep in [*self._writers.values(), *self._readers.values()]:
                if ep.data.topic != "DCPS":
                    self._try_match(ep, data, events)
        self._notify(events)

    # -- receiving ---------------------------------------------------------------------------

    def _receive_meta(self) -> None:
        socks = [self.meta_sock] + ([self.mc_sock] if self.mc_sock is not None else [])
        self._receive_loop(socks)

    def _receive_user(self) -> None:
        self._receive_loop([self.user_sock])

    def _receive_loop(self, socks: List[socket.socket]) -> None:
        buf = bytearray(65536)
        view = memoryview(buf)
        sel = selectors.DefaultSelector()
        for s in socks:
            s.setblocking(False)
            sel.register(s, selectors.EVENT_READ)
        sel.register(self._wake_r, selectors.EVENT_READ)
        try:
            while not self._closed:
                for key, _ in sel.select():
                    if self._closed:
                        return
                    if key.fileobj == self._wake_r:
                        continue
                    sock = key.fileobj
                    assert isinstance(sock, socket.socket)
                    while not self._closed:
                        try:
                            n, addr = sock.recvfrom_into(buf)
                        except (BlockingIOError, InterruptedError):
                            break
                        except OSError:
                            if self._closed:
                                return
                            break
                        self._on_datagram(view[:n], addr)
        finally:
            sel.close()

    def _on_datagram(self, view: memoryview, addr: Tuple[str, int]) -> None:
        try:
            msg = m.parse_message(view)
        except m.MalformedMessage as exc:
            self._report_bad(f"{addr[0]}:{addr[1]}", str(exc))
            return
        if msg.prefix == self.prefix:
            return
        now = time.monotonic()
        remote = self._remotes.get(msg.prefix)
        if remote is not None:
            remote.last_seen = now
        if msg.error is not None:
            self._report_bad(f"{addr[0]}:{addr[1]}", msg.error)
        touched: Dict[bytes, LocalWriter] = {}
        out: List[Datagram] = []
        mine = self.prefix
        for sub in msg.submessages:
            if sub.dst is not None and sub.dst != mine:
                continue
            kind = sub.kind
            if kind == m.DATA:
                assert isinstance(sub, m.Data)
                if sub.writer_id == g.SPDP_WRITER:
                    self._on_spdp(sub, now)
                    continue
                for reader in self._route(sub.src + sub.writer_id, sub.reader_id):
                    with reader.lock:
                        samples = reader.machine.on_data(sub, now)
                    if samples:
                        reader._deliver(samples)
            elif kind == m.DATA_FRAG:
                assert isinstance(sub, m.DataFrag)
                for reader in self._route(sub.src + sub.writer_id, sub.reader_id):
                    with reader.lock:
                        samples = reader.machine.on_data_frag(sub, now)
                        if not samples and sub.start + sub.count > sub.total:
                            # its last fragment came, others did not: ask for them now
                            out += reader.machine.nack_partial(sub.src + sub.writer_id)
                        due = reader.machine.next_deadline()
                    if samples:
                        reader._deliver(samples)
                    if due is not None:
                        self._wake_timer(due)
            elif kind == m.HEARTBEAT:
                assert isinstance(sub, m.Heartbeat)
                for reader in self._route(sub.src + sub.writer_id, sub.reader_id):
                    with reader.lock:
                        samples, answer = reader.machine.on_heartbeat(sub, now)
                        due = reader.machine.next_deadline()
                    out += answer
                    if due is not None:
                        self._wake_timer(due)
                    if samples:
                        reader._deliver(samples)
            elif kind == m.GAP:
                assert isinstance(sub, m.Gap)
                for reader in self._route(sub.src + sub.writer_id, sub.reader_id):
                    with reader.lock:
                        samples = reader.machine.on_gap(sub)
                    if samples:
                        reader._deliver(samples)
            elif kind == m.HEARTBEAT_FRAG:
                assert isinstance(sub, m.HeartbeatFrag)
                for reader in self._route(sub.src + sub.writer_id, sub.reader_id):
                    with reader.lock:
                        out += reader.machine.on_heartbeat_frag(sub, now)
            elif kind == m.ACKNACK or kind == m.NACK_FRAG:
                writer = self._writers.get(sub.writer_id)  # type: ignore[attr-defined]
                if writer is None:
                    continue
                with writer.lock:
                    if kind == m.ACKNACK:
                        writer.machine.on_acknack(sub, now)  # type: ignore[arg-type]
                    else:
                        writer.machine.on_nack_frag(sub, now)  # type: ignore[arg-type]
                touched[sub.writer_id] = writer  # type: ignore[attr-defined]
        for writer in touched.values():
            with writer.lock:
                out += writer.machine.answer(now)
                due = writer.machine.next_deadline()
                writer.changed.notify_all()
            if due is not None:
                self._wake_timer(due)
        if out:
            self._send(out)

    def _route(self, writer_guid: bytes, reader_id: bytes) -> List[LocalReader]:
        readers = self._readers_by_writer.get(writer_guid)
        if not readers:
            return []
        if reader_id == g.ENTITYID_UNKNOWN:
            return list(readers)
        return [r for r in readers if r.guid[12:] == reader_id]

    def _report_bad(self, source: str, what: str) -> None:
        """One line per peer and minute for input that does not decode."""
        now = time.monotonic()
        last = self._bad_input.get(source)
        if last is not None and now - last < 60:
            return
        if len(self._bad_input) > 1024:
            self._bad_input.clear()
        self._bad_input[source] = now
        log.warning("ROS 2: ignored a datagram from %s: %s", source, what)

    # -- sending -----------------------------------------------------------------------------

    def _send(self, datagrams: Sequence[Datagram]) -> None:
        sock = self._send_sock
        for dg in datagrams:
            for addr in dg.addresses:
                try:
                    sock.sendmsg(dg.buffers, (), 0, addr)
                except (BlockingIOError, InterruptedError):
                    # the send buffer is full: wait for room once, then drop (UDP may)
                    try:
                        select.select([], [sock], [], 0.05)
                        sock.sendmsg(dg.buffers, (), 0, addr)
                    except OSError:
                        pass
                except OSError as exc:
                    if self._closed:
                        return
                    self._report_bad(f"{addr[0]}:{addr[1]}", f"cannot send there: {exc.strerror}")

    # -- time --------------------------------------------------------------------------------

    def _wake_timer(self, when: float) -> None:
        if when < self._timer_target:
            self._timer_target = when
            self._timer_event.set()

    def _timer(self) -> None:
        self._next_announce = time.monotonic()
        self._next_lease_check = time.monotonic() + 1.0
        while not self._closed:
            # awake: any new deadline wakes the next wait (_timer_target is infinite)
            self._timer_event.clear()
            self._timer_target = float("inf")
            now = time.monotonic()
            if now >= self._next_announce:
                self._send(self._spdp_datagrams())
                if self._announce_left > 0:
                    self._announce_left -= 1
                    self._next_announce = now + 0.1
                else:
                    self._next_announce = now + self.announce_period
            if now >= self._next_lease_check:
                self._check_leases(now)
                self._next_lease_check = now + 1.0
            out: List[Datagram] = []
            target = min(self._next_announce, self._next_lease_check)
            with self._lock:
                writers = list(self._writers.values())
                readers = list(self._readers.values())
            for writer in writers:
                with writer.lock:
                    due = writer.machine.next_deadline()
                    if due is not None and due <= now:
                        out += writer.machine.tick(now)
                        due = writer.machine.next_deadline()
                if due is not None:
                    target = min(target, due)
            # a reader that looks stalled may only be behind: what is in its socket first
            behind = _readable(self.user_sock)
            for reader in readers:
                with reader.lock:
                    due = reader.machine.next_deadline()
                    late: List[Sample] = []
                    if due is not None and due <= now and not behind:
                        out += reader.machine.tick(now)
                        late = reader.machine.take_late()
                        due = reader.machine.next_deadline()
                if late:
                    reader._deliver(late)
                if due is not None:
                    target = min(target, due)
            if out:
                self._send(out)
            if behind:
                target = min(target, now + 0.002)
            self._timer_target = target
            wait = target - time.monotonic()
            if wait > 0:
                self._timer_event.wait(wait)

    def _check_leases(self, now: float) -> None:
        with self._lock:
            expired = [(r.prefix, r.data.lease_duration) for r in self._remotes.values()
                       if now - r.last_seen > r.data.lease_duration]
        for prefix, lease in expired:
            self._remove_participant(prefix, f"is gone: nothing heard from it for its lease "
                                             f"of {lease:g} s")


def _multicast_capable(host: str) -> bool:
    """Whether the interface that has address ``host`` has the MULTICAST flag (Linux
    ioctls; elsewhere, or when no interface has it, True: multicast is tried)."""
    try:
        import fcntl
        import struct

        probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    except (ImportError, OSError):
        return True
    try:
        for _, name in socket.if_nameindex():
            raw = name.encode()[:15]
            try:
                addr = fcntl.ioctl(probe.fileno(), 0x8915, struct.pack("16sH14s", raw, 0,
                                                                       b""))  # SIOCGIFADDR
            except OSError:
                continue
            if socket.inet_ntoa(addr[20:24]) != host:
                continue
            flags = fcntl.ioctl(probe.fileno(), 0x8913, struct.pack("16sH", raw, 0))
            return bool(struct.unpack("16sH", flags[:18])[1] & 0x1000)  # IFF_MULTICAST
        return True
    finally:
        probe.close()


def _readable(sock: socket.socket) -> bool:
    """Whether datagrams wait in ``sock`` (its receive thread has not read them yet)."""
    try:
        return bool(select.select([sock], [], [], 0)[0])
    except (OSError, ValueError):
        return False


def _udp_socket() -> socket.socket:
    return socket.socket(socket.AF_INET, socket.SOCK_DGRAM)


def _grow_buffers(sock: socket.socket) -> int:
    """Ask for large socket buffers (the kernel caps them); the receive size it gave."""
    for opt in (socket.SO_RCVBUF, socket.SO_SNDBUF):
        try:
            sock.setsockopt(socket.SOL_SOCKET, opt, SOCKET_BUFFER)
        except OSError:
            pass
    return int(sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF))

