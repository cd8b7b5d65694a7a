"""Discovery data without I/O: SPDP's participant data, SEDP's publication and subscription
data, the QoS they carry, the QoS matching rules, and the port mapping.

DDS discovers in two steps (DDSI-RTPS 8.5):

* **SPDP** (participants): each participant sends its :class:`ParticipantData` (GUID prefix,
  vendor, where it receives discovery traffic and user data, its lease, which built-in
  endpoints it has) to the multicast group 239.255.0.1 and to the unicast ports of its peers,
  again every few seconds; a participant not heard from within its lease is gone.
* **SEDP** (endpoints): each participant's built-in publications and subscriptions writers
  send one :class:`EndpointData` per user writer or reader (topic, type, QoS, locators,
  USER_DATA) reliably to every peer's matching built-in reader, transient-local.

A writer and a reader match when topic and type names are equal and the writer's offered QoS
satisfies the reader's requested QoS (:func:`incompatibility` says why not, in words).
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field, replace
from typing import Callable, Dict, List, Optional, Tuple

from minros.ros2.rtps import guid as g
from minros.ros2.rtps import params as p
from minros.ros2.rtps.params import Locator, ParamError, ParamWriter

__all__ = [
    "BEST_EFFORT", "BUILTIN_ENDPOINTS", "DiscoveryError", "EndpointData", "KEEP_ALL",
    "KEEP_LAST", "ParticipantData", "Qos", "RELIABLE", "TRANSIENT_LOCAL", "VOLATILE",
    "decode_endpoint", "decode_participant", "encode_endpoint", "encode_participant",
    "incompatibility", "key_payload", "metatraffic_multicast_port", "metatraffic_unicast_port",
    "user_unicast_port",
]

# -- the port mapping (RTPS 9.6.1.1): PB + DG * domain + offset (+ PG * participant id) -------
PB, DG, PG, D0, D1, D2, D3 = 7400, 250, 2, 0, 10, 1, 11
SPDP_MULTICAST_GROUP = "239.255.0.1"


def metatraffic_multicast_port(domain: int) -> int:
    return PB + DG * domain + D0


def metatraffic_unicast_port(domain: int, participant_id: int) -> int:
    return PB + DG * domain + D1 + PG * participant_id


def user_unicast_port(domain: int, participant_id: int) -> int:
    return PB + DG * domain + D3 + PG * participant_id


# -- built-in endpoint set bits (RTPS 9.3.2 table 9.4) ----------------------------------------
PARTICIPANT_ANNOUNCER = 1 << 0
PARTICIPANT_DETECTOR = 1 << 1
PUBLICATIONS_ANNOUNCER = 1 << 2
PUBLICATIONS_DETECTOR = 1 << 3
SUBSCRIPTIONS_ANNOUNCER = 1 << 4
SUBSCRIPTIONS_DETECTOR = 1 << 5
#: what minros has: SPDP and SEDP's publications and subscriptions, both directions (no
#: writer-liveliness endpoints: ROS 2's default liveliness is automatic with no lease)
BUILTIN_ENDPOINTS = (PARTICIPANT_ANNOUNCER | PARTICIPANT_DETECTOR | PUBLICATIONS_ANNOUNCER
                     | PUBLICATIONS_DETECTOR | SUBSCRIPTIONS_ANNOUNCER | SUBSCRIPTIONS_DETECTOR)

# -- QoS ---------------------------------------------------------------------------------------
BEST_EFFORT = 1
RELIABLE = 2
VOLATILE = 0
TRANSIENT_LOCAL = 1
TRANSIENT = 2
PERSISTENT = 3
KEEP_LAST = 0
KEEP_ALL = 1
AUTOMATIC = 0
MANUAL_BY_PARTICIPANT = 1
MANUAL_BY_TOPIC = 2
XCDR1 = 0
XCDR2 = 2

_RELIABILITY = {BEST_EFFORT: "BEST_EFFORT", RELIABLE: "RELIABLE"}
_DURABILITY = {VOLATILE: "VOLATILE", TRANSIENT_LOCAL: "TRANSIENT_LOCAL", TRANSIENT: "TRANSIENT",
               PERSISTENT: "PERSISTENT"}
_LIVELINESS = {AUTOMATIC: "AUTOMATIC", MANUAL_BY_PARTICIPANT: "MANUAL_BY_PARTICIPANT",
               MANUAL_BY_TOPIC: "MANUAL_BY_TOPIC"}


class DiscoveryError(ValueError):
    """Discovery data that does not decode; ``str()`` says what was wrong."""


@dataclass(frozen=True)
class Qos:
    """The QoS of one endpoint as SEDP carries it. Durations are seconds (``math.inf``:
    infinite). The defaults are the spec's for a parameter absent from a writer's data (a
    reader's absent reliability means BEST_EFFORT: :func:`decode_endpoint` applies that)."""

    reliability: int = RELIABLE
    max_blocking_time: float = 0.1
    durability: int = VOLATILE
    history: int = KEEP_LAST
    depth: int = 1
    deadline: float = math.inf
    lifespan: float = math.inf
    liveliness: int = AUTOMATIC
    lease_duration: float = math.inf
    ownership: int = 0
    destination_order: int = 0
    partitions: Tuple[str, ...] = ()
    data_representation: Tuple[int, ...] = ()

    def describe(self) -> str:
        """The QoS in ROS 2's words, for log lines: "RELIABLE, TRANSIENT_LOCAL, KEEP_LAST 1"."""
        history = "KEEP_ALL" if self.history == KEEP_ALL else f"KEEP_LAST {self.depth}"
        text = (f"{_RELIABILITY.get(self.reliability, self.reliability)}, "
                f"{_DURABILITY.get(self.durability, self.durability)}, {history}")
        if not math.isinf(self.deadline):
            text += f", deadline {self.deadline:g} s"
        if self.liveliness != AUTOMATIC or not math.isinf(self.lease_duration):
            text += (f", liveliness {_LIVELINESS.get(self.liveliness, self.liveliness)} "
                     f"{self.lease_duration:g} s")
        return text


def incompatibility(offered: Qos, requested: Qos) -> Optional[str]:
    """Why a writer offering ``offered`` cannot serve a reader requesting ``requested`` (the
    DDS request/offer rules, DDS 1.4 2.2.3), or None when they match."""
    if offered.reliability < requested.reliability:
        return (f"reliability: the writer offers {_RELIABILITY[offered.reliability]}, the "
                f"reader requests {_RELIABILITY[requested.reliability]}")
    if offered.durability < requested.durability:
        return (f"durability: the writer offers {_DURABILITY[offered.durability]}, the reader "
                f"requests {_DURABILITY[requested.durability]}")
    if offered.deadline > requested.deadline:
        return (f"deadline: the writer offers {offered.deadline:g} s, the reader requests "
                f"{requested.deadline:g} s")
    if offered.liveliness < requested.liveliness:
        return (f"liveliness: the writer offers {_LIVELINESS[offered.liveliness]}, the reader "
                f"requests {_LIVELINESS[requested.liveliness]}")
    if offered.lease_duration > requested.lease_duration:
        return (f"liveliness lease: the writer offers {offered.lease_duration:g} s, the reader "
                f"requests {requested.lease_duration:g} s")
    if offered.ownership != requested.ownership:
        return "ownership: one side is EXCLUSIVE, the other SHARED"
    if offered.destination_order < requested.destination_order:
        return "destination order: the reader requests BY_SOURCE_TIMESTAMP"
    if not _partitions_meet(offered.partitions, requested.partitions):
        return (f"partitions: the writer is in {list(offered.partitions) or ['']}, the reader "
                f"in {list(requested.partitions) or ['']}")
    writer_rep = offered.data_representation[0] if offered.data_representation else XCDR1
    if writer_rep not in (requested.data_representation or (XCDR1,)):
        return (f"data representation: the writer writes XCDR{2 if writer_rep == XCDR2 else 1}"
                f", the reader accepts {list(requested.data_representation)}")
    return None


def _partitions_meet(a: Tuple[str, ...], b: Tuple[str, ...]) -> bool:
    import fnmatch

    left, right = a or ("",), b or ("",)
    return any(x == y or fnmatch.fnmatchcase(x, y) or fnmatch.fnmatchcase(y, x)
               for x in left for y in right)


# -- SPDP --------------------------------------------------------------------------------------

@dataclass
class ParticipantData:
    """What SPDP says about a participant."""

    prefix: bytes
    vendor: bytes = g.VENDOR_MINROS
    version: Tuple[int, int] = (2, 4)
    domain_id: Optional[int] = None
    metatraffic_unicast: List[Locator] = field(default_factory=list)
    metatraffic_multicast: List[Locator] = field(default_factory=list)
    default_unicast: List[Locator] = field(default_factory=list)
    default_multicast: List[Locator] = field(default_factory=list)
    lease_duration: float = 100.0
    builtin_endpoints: int = BUILTIN_ENDPOINTS
    user_data: bytes = b""
    entity_name: Optional[str] = None
    #: vendor-specific parameters, kept as they came (pid, value)
    vendor_params: List[Tuple[int, bytes]] = field(default_factory=list)

    @property
    def guid(self) -> bytes:
        return self.prefix + g.ENTITYID_PARTICIPANT


def encode_participant(data: ParticipantData) -> bytes:
    """The SPDP sample (PL_CDR_LE encapsulation and parameter list)."""
    w = ParamWriter()
    w.add(p.PID_PROTOCOL_VERSION, bytes(data.version) + b"\0\0")
    w.add(p.PID_VENDORID, bytes(data.vendor) + b"\0\0")
    w.add(p.PID_PARTICIPANT_GUID, data.guid)
    if data.domain_id is not None:
        w.u32(p.PID_DOMAIN_ID, data.domain_id)
    for pid, locators in ((p.PID_METATRAFFIC_UNICAST_LOCATOR, data.metatraffic_unicast),
                          (p.PID_METATRAFFIC_MULTICAST_LOCATOR, data.metatraffic_multicast),
                          (p.PID_DEFAULT_UNICAST_LOCATOR, data.default_unicast),
                          (p.PID_DEFAULT_MULTICAST_LOCATOR, data.default_multicast)):
        for loc in locators:
            w.locator(pid, loc)
    w.duration(p.PID_PARTICIPANT_LEASE_DURATION, data.lease_duration)
    w.u32(p.PID_BUILTIN_ENDPOINT_SET, data.builtin_endpoints)
    if data.entity_name is not None:
        w.string(p.PID_ENTITY_NAME, data.entity_name)
    if data.user_data:
        w.octets(p.PID_USER_DATA, data.user_data)
    return b"\x00\x03\x00\x00" + w.encode()


def _plist(payload: memoryview) -> Tuple[p.ParamList, bool]:
    if len(payload) < 4:
        raise DiscoveryError("a discovery sample shorter than its encapsulation header")
    kind = payload[1] | payload[0] << 8
    if kind not in (0x0002, 0x0003):
        raise DiscoveryError(f"encapsulation 0x{kind:04x}: discovery data is PL_CDR (2 or 3)")
    little = kind == 0x0003
    try:
        return p.parse_params(payload[4:], little), little
    except ParamError as exc:
        raise DiscoveryError(str(exc)) from None


def decode_participant(payload: memoryview) -> ParticipantData:
    """An SPDP sample. Raises DiscoveryError (what was wrong) for one that does not decode."""
    plist, le = _plist(payload)
    data = ParticipantData(prefix=b"", lease_duration=100.0, builtin_endpoints=0, version=(2, 0),
                           vendor=g.ENTITYID_UNKNOWN[:2])
    try:
        for pid, value in plist:
            if pid == p.PID_PARTICIPANT_GUID:
                data.prefix = p.decode_guid(value)[:12]
            elif pid == p.PID_PROTOCOL_VERSION:
                data.version = (value[0], value[1])
            elif pid == p.PID_VENDORID:
                data.vendor = bytes(value[:2])
            elif pid == p.PID_DOMAIN_ID:
                data.domain_id = p.decode_u32(value, le)
            elif pid == p.PID_METATRAFFIC_UNICAST_LOCATOR:
                data.metatraffic_unicast.append(p.decode_locator(value, le))
            elif pid == p.PID_METATRAFFIC_MULTICAST_LOCATOR:
                data.metatraffic_multicast.append(p.decode_locator(value, le))
            elif pid == p.PID_DEFAULT_UNICAST_LOCATOR:
                data.default_unicast.append(p.decode_locator(value, le))
            elif pid == p.PID_DEFAULT_MULTICAST_LOCATOR:
                data.default_multicast.append(p.decode_locator(value, le))
            elif pid == p.PID_PARTICIPANT_LEASE_DURATION:
                data.lease_duration = p.decode_duration(value, le)
            elif pid == p.PID_BUILTIN_ENDPOINT_SET:
                data.builtin_endpoints = p.decode_u32(value, le)
            elif pid == p.PID_USER_DATA:
                data.user_data = p.decode_octets(value, le)
            elif pid == p.PID_ENTITY_NAME:
                data.entity_name = p.decode_string(value, le)
            elif pid & p.VENDOR_SPECIFIC:
                data.vendor_params.append((pid, bytes(value)))
    except (ParamError, IndexError) as exc:
        raise DiscoveryError(f"participant data: {exc}") from None
    if len(data.prefix) != 12:
        raise DiscoveryError("participant data without PID_PARTICIPANT_GUID")
    return data


# -- SEDP --------------------------------------------------------------------------------------

@dataclass
class EndpointData:
    """What SEDP says about one writer (a publication) or reader (a subscription)."""

    guid: bytes
    topic: str
    type_name: str
    qos: Qos = field(default_factory=Qos)
    unicast: List[Locator] = field(default_factory=list)
    multicast: List[Locator] = field(default_factory=list)
    user_data: bytes = b""
    expects_inline_qos: bool = False
    vendor: bytes = b""
    #: XTypes type information, kept opaque (minros matches by type name, as rmw does)
    type_information: Optional[bytes] = None

    @property
    def participant_prefix(self) -> bytes:
        return self.guid[:12]

    @property
    def is_reader(self) -> bool:
        return g.is_reader(self.guid[12:])

    def user_data_value(self, key: str) -> Optional[str]:
        """A ``key=value;`` entry of USER_DATA (rmw's ``typehash``, ``clientid``...)."""
        return user_data_value(self.user_data, key)


def user_data_value(user_data: bytes, key: str) -> Optional[str]:
    text = user_data.rstrip(b"\0").decode(errors="replace")
    for item in text.split(";"):
        name, sep, value = item.partition("=")
        if sep and name == key:
            return value
    return None


def encode_endpoint(data: EndpointData, participant_guid: bytes) -> bytes:
    """The SEDP sample of one endpoint (PL_CDR_LE)."""
    q = data.qos
    w = ParamWriter()
    w.add(p.PID_ENDPOINT_GUID, data.guid)
    w.add(p.PID_PARTICIPANT_GUID, participant_guid)
    w.string(p.PID_TOPIC_NAME, data.topic)
    w.string(p.PID_TYPE_NAME, data.type_name)
    w.add(p.PID_KEY_HASH, data.guid)
    w.add(p.PID_PROTOCOL_VERSION, bytes((2, 4)) + b"\0\0")
    w.add(p.PID_VENDORID, g.VENDOR_MINROS + b"\0\0")
    for loc in data.unicast:
        w.locator(p.PID_UNICAST_LOCATOR, loc)
    for loc in data.multicast:
        w.locator(p.PID_MULTICAST_LOCATOR, loc)
    w.add(p.PID_RELIABILITY, struct.pack("<I", q.reliability) + p.duration_bytes(q.max_blocking_time))
    w.u32(p.PID_DURABILITY, q.durability)
    w.add(p.PID_HISTORY, struct.pack("<Ii", q.history, q.depth))
    w.duration(p.PID_DEADLINE, q.deadline)
    w.duration(p.PID_LIFESPAN, q.lifespan)
    w.add(p.PID_LIVELINESS, struct.pack("<I", q.liveliness) + p.duration_bytes(q.lease_duration))
    if q.ownership:
        w.u32(p.PID_OWNERSHIP, q.ownership)
    if q.partitions:
        w.add(p.PID_PARTITION, p.strings_bytes(q.partitions))
    if q.data_representation:
        w.add(p.PID_DATA_REPRESENTATION, p.shorts_bytes(q.data_representation))
    if data.is_reader:
        w.u32(p.PID_EXPECTS_INLINE_QOS, 1 if data.expects_inline_qos else 0)
    if data.user_data:
        w.octets(p.PID_USER_DATA, data.user_data)
    return b"\x00\x03\x00\x00" + w.encode()


def decode_endpoint(payload: memoryview, vendor: bytes = b"") -> EndpointData:
    """An SEDP sample (publication or subscription). Raises DiscoveryError."""
    plist, le = _plist(payload)
    guid = b""
    topic: Optional[str] = None
    type_name: Optional[str] = None
    qos: Dict[str, object] = {}
    out = EndpointData(guid=b"", topic="", type_name="", vendor=bytes(vendor))
    u32 = struct.Struct("<I" if le else ">I")
    try:
        for pid, value in plist:
            if pid == p.PID_ENDPOINT_GUID:
                guid = p.decode_guid(value)
            elif pid == p.PID_TOPIC_NAME:
                topic = p.decode_string(value, le)
            elif pid == p.PID_TYPE_NAME:
                type_name = p.decode_string(value, le)
            elif pid == p.PID_UNICAST_LOCATOR:
                out.unicast.append(p.decode_locator(value, le))
            elif pid == p.PID_MULTICAST_LOCATOR:
                out.multicast.append(p.decode_locator(value, le))
            elif pid == p.PID_RELIABILITY:
                qos["reliability"] = p.decode_u32(value, le)
                if len(value) >= 12:
                    qos["max_blocking_time"] = p.decode_duration(value[4:], le)
            elif pid == p.PID_DURABILITY:
                qos["durability"] = p.decode_u32(value, le)
            elif pid == p.PID_HISTORY:
                qos["history"] = p.decode_u32(value, le)
                if len(value) >= 8:
                    qos["depth"] = struct.unpack_from("<i" if le else ">i", value, 4)[0]
            elif pid == p.PID_DEADLINE:
                qos["deadline"] = p.decode_duration(value, le)
            elif pid == p.PID_LIFESPAN:
                qos["lifespan"] = p.decode_duration(value, le)
            elif pid == p.PID_LIVELINESS:
                qos["liveliness"] = p.decode_u32(value, le)
                if len(value) >= 12:
                    qos["lease_duration"] = p.decode_duration(value[4:], le)
            elif pid == p.PID_OWNERSHIP:
                qos["ownership"] = p.decode_u32(value, le)
            elif pid == p.PID_DESTINATION_ORDER:
                qos["destination_order"] = p.decode_u32(value, le)
            elif pid == p.PID_PARTITION:
                qos["partitions"] = tuple(p.decode_strings(value, le))
            elif pid == p.PID_DATA_REPRESENTATION:
                qos["data_representation"] = tuple(p.decode_shorts(value, le))
            elif pid == p.PID_USER_DATA:
                out.user_data = p.decode_octets(value, le)
            elif pid == p.PID_EXPECTS_INLINE_QOS:
                out.expects_inline_qos = p.decode_bool(value)
            elif pid == p.PID_TYPE_INFORMATION:
                out.type_information = bytes(value)
            elif pid == p.PID_VENDORID and not out.vendor:
                out.vendor = bytes(value[:2])
    except (ParamError, IndexError, struct.error) as exc:
        raise DiscoveryError(f"endpoint data: {exc}") from None
    del u32
    if len(guid) != 16:
        raise DiscoveryError("endpoint data without PID_ENDPOINT_GUID")
    if topic is None or type_name is None:
        raise DiscoveryError(f"endpoint {g.guid_text(guid)} without its topic or type name")
    out.guid, out.topic, out.type_name = guid, topic, type_name
    if g.is_reader(guid[12:]):
        qos.setdefault("reliability", BEST_EFFORT)  # a reader's default (RTPS table 9.12)
    out.qos = replace(Qos(), **qos)  # type: ignore[arg-type]
    return out


def key_payload(pid: int, key: bytes) -> bytes:
    """The serialized key of a built-in topic sample (a dispose carries it, flag K)."""
    return b"\x00\x03\x00\x00" + ParamWriter().add(pid, key).encode()


def describe_user_data(user_data: bytes, keys: Tuple[str, ...] = ("typehash",),
                       fmt: Callable[[str], str] = str) -> str:
    parts = [f"{k}={fmt(v)}" for k in keys if (v := user_data_value(user_data, k)) is not None]
    return ", ".join(parts)
