"""Parameter lists (RTPS 9.4.2.11): the ``PID_*`` records discovery data and inline QoS are
made of, their value encodings, and locators.

A parameter list is a run of ``pid (2) | length (2) | value`` records, each value padded to 4
bytes, ended by ``PID_SENTINEL``. Discovery samples are parameter lists in a PL_CDR
encapsulation (``00 03 00 00``: little-endian); inline QoS is one in the submessage's own byte
order. PIDs with bit 0x8000 are the sending vendor's own (Fast DDS's 0x8007, Cyclone's
0x8001...): read only from that vendor, so this module gives them back untouched.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from typing import Iterable, List, Optional, Sequence, Tuple

__all__ = [
    "Locator", "ParamError", "ParamList", "ParamWriter", "decode_bool", "decode_duration",
    "decode_guid", "decode_locator", "decode_octets", "decode_string", "decode_strings",
    "decode_u32", "duration_bytes", "parse_params",
]

PID_PAD = 0x0000
PID_SENTINEL = 0x0001
PID_PARTICIPANT_LEASE_DURATION = 0x0002
PID_TOPIC_NAME = 0x0005
PID_TYPE_NAME = 0x0007
PID_DOMAIN_ID = 0x000F
PID_PROTOCOL_VERSION = 0x0015
PID_VENDORID = 0x0016
PID_RELIABILITY = 0x001A
PID_LIVELINESS = 0x001B
PID_DURABILITY = 0x001D
PID_DURABILITY_SERVICE = 0x001E
PID_OWNERSHIP = 0x001F
PID_PRESENTATION = 0x0021
PID_DEADLINE = 0x0023
PID_DESTINATION_ORDER = 0x0025
PID_LATENCY_BUDGET = 0x0027
PID_PARTITION = 0x0029
PID_LIFESPAN = 0x002B
PID_USER_DATA = 0x002C
PID_GROUP_DATA = 0x002D
PID_TOPIC_DATA = 0x002E
PID_UNICAST_LOCATOR = 0x002F
PID_MULTICAST_LOCATOR = 0x0030
PID_DEFAULT_UNICAST_LOCATOR = 0x0031
PID_METATRAFFIC_UNICAST_LOCATOR = 0x0032
PID_METATRAFFIC_MULTICAST_LOCATOR = 0x0033
PID_PARTICIPANT_MANUAL_LIVELINESS_COUNT = 0x0034
PID_HISTORY = 0x0040
PID_RESOURCE_LIMITS = 0x0041
PID_EXPECTS_INLINE_QOS = 0x0043
PID_BUILTIN_ENDPOINT_QOS = 0x0077
PID_DEFAULT_MULTICAST_LOCATOR = 0x0048
PID_TRANSPORT_PRIORITY = 0x0049
PID_PARTICIPANT_GUID = 0x0050
PID_GROUP_GUID = 0x0052
PID_BUILTIN_ENDPOINT_SET = 0x0058
PID_PROPERTY_LIST = 0x0059
PID_ENDPOINT_GUID = 0x005A
PID_TYPE_MAX_SIZE_SERIALIZED = 0x0060
PID_ENTITY_NAME = 0x0062
PID_KEY_HASH = 0x0070
PID_STATUS_INFO = 0x0071
PID_DATA_REPRESENTATION = 0x0073
PID_TYPE_CONSISTENCY_ENFORCEMENT = 0x0074
PID_TYPE_INFORMATION = 0x0075
#: DDS-RPC's, as Fast DDS and minros put a request's and a reply's identity inline
PID_RELATED_SAMPLE_IDENTITY = 0x0083
PID_DOMAIN_TAG = 0x4014
#: bit 0x4000: a receiver that does not understand the parameter must drop the sample
MUST_UNDERSTAND = 0x4000
VENDOR_SPECIFIC = 0x8000

#: at most this many records in one list (a 64 KiB datagram holds at most 16384 empty ones)
MAX_PARAMS = 4096

LOCATOR_KIND_UDPV4 = 1
LOCATOR_KIND_UDPV6 = 2


class ParamError(ValueError):
    """A parameter list or value that does not decode; ``str()`` says which and why."""


@dataclass(frozen=True)
class Locator:
    """Where a participant or endpoint receives: kind (1 UDPv4, 2 UDPv6, Fast DDS's 16 shared
    memory, ...), port, and a 16-byte address (an IPv4 one is its last 4)."""

    kind: int
    port: int
    address: bytes

    @classmethod
    def udpv4(cls, host: str, port: int) -> Locator:
        return cls(LOCATOR_KIND_UDPV4, port, bytes(12) + bytes(int(p) for p in host.split(".")))

    @property
    def host(self) -> str:
        """The IPv4 address as text (UDPv4 locators), else the address's hex."""
        if self.kind == LOCATOR_KIND_UDPV4:
            return ".".join(str(b) for b in self.address[12:])
        return self.address.hex()

    def encode(self) -> bytes:
        return struct.pack("<iI", self.kind, self.port) + self.address

    def __str__(self) -> str:
        return f"udpv4:{self.host}:{self.port}" if self.kind == 1 else \
            f"kind{self.kind}:{self.address.hex()}:{self.port}"


ParamList = List[Tuple[int, memoryview]]


def parse_params(buf: memoryview, little: bool) -> ParamList:
    """The records of the parameter list in ``buf`` (which may continue past the sentinel),
    as (pid, value) with each value a view of ``buf``. Raises ParamError."""
    fmt = struct.Struct("<HH" if little else ">HH")
    out: ParamList = []
    pos, end = 0, len(buf)
    while True:
        if pos + 4 > end:
            raise ParamError("a parameter list without its sentinel")
        pid, plen = fmt.unpack_from(buf, pos)
        pos += 4
        if pid == PID_SENTINEL:
            return out
        if pos + plen > end:
            raise ParamError(f"parameter 0x{pid:04x} announces {plen} bytes, {end - pos} left")
        if pid != PID_PAD:
            out.append((pid, buf[pos:pos + plen]))
            if len(out) > MAX_PARAMS:
                raise ParamError(f"more than {MAX_PARAMS} parameters")
        pos += plen


class ParamWriter:
    """Builds a little-endian parameter list (records padded to 4 bytes)."""

    def __init__(self) -> None:
        self._parts: List[bytes] = []

    def add(self, pid: int, value: bytes) -> ParamWriter:
        pad = -len(value) % 4
        if len(value) + pad > 0xFFFF:
            raise ParamError(f"parameter 0x{pid:04x} of {len(value)} bytes does not fit")
        self._parts.append(struct.pack("<HH", pid, len(value) + pad) + value + b"\0" * pad)
        return self

    def u32(self, pid: int, value: int) -> ParamWriter:
        return self.add(pid, struct.pack("<I", value))

    def string(self, pid: int, text: str) -> ParamWriter:
        return self.add(pid, string_bytes(text))

    def octets(self, pid: int, value: bytes) -> ParamWriter:
        return self.add(pid, struct.pack("<I", len(value)) + value)

    def locator(self, pid: int, locator: Locator) -> ParamWriter:
        return self.add(pid, locator.encode())

    def duration(self, pid: int, seconds: float) -> ParamWriter:
        return self.add(pid, duration_bytes(seconds))

    def encode(self) -> bytes:
        """The list with its sentinel."""
        return b"".join(self._parts) + struct.pack("<HH", PID_SENTINEL, 0)


def string_bytes(text: str) -> bytes:
    raw = text.encode() + b"\0"
    return struct.pack("<I", len(raw)) + raw


#: Duration_t INFINITE (seconds 0x7fffffff, fraction 0xffffffff)
_INFINITE = (0x7FFFFFFF, 0xFFFFFFFF)


def duration_bytes(seconds: float) -> bytes:
    """An RTPS Duration_t (int32 seconds, uint32 2^-32 fractions); ``math.inf`` is INFINITE."""
    if math.isinf(seconds) or seconds >= 0x7FFFFFFF:
        return struct.pack("<iI", *_INFINITE)
    whole = math.floor(seconds)
    frac = min(int(round((seconds - whole) * (1 << 32))), 0xFFFFFFFF)
    return struct.pack("<iI", whole, frac)


def _need(value: memoryview, size: int, what: str) -> None:
    if len(value) < size:
        raise ParamError(f"{what}: {len(value)} bytes, {size} needed")


def decode_u32(value: memoryview, little: bool) -> int:
    _need(value, 4, "a uint32 parameter")
    return int(struct.unpack_from("<I" if little else ">I", value)[0])


def decode_bool(value: memoryview) -> bool:
    _need(value, 1, "a boolean parameter")
    return bool(value[0])


def decode_duration(value: memoryview, little: bool) -> float:
    """A Duration_t as seconds (``math.inf`` for INFINITE)."""
    _need(value, 8, "a duration")
    sec, frac = struct.unpack_from("<iI" if little else ">iI", value)
    if (sec, frac) == _INFINITE or sec == 0x7FFFFFFF:
        return math.inf
    return float(round(sec + frac / (1 << 32), 9))  # to the nanosecond: DDS's own unit


def decode_string(value: memoryview, little: bool) -> str:
    """A CDR string (uint32 length with its NUL, the bytes, the NUL)."""
    text, _ = _string_at(value, 0, little)
    return text


def _string_at(value: memoryview, pos: int, little: bool) -> Tuple[str, int]:
    _need(value[pos:], 4, "a string")
    (n,) = struct.unpack_from("<I" if little else ">I", value, pos)
    if n < 1 or pos + 4 + n > len(value):
        raise ParamError(f"a string of {n} bytes in {len(value) - pos - 4}")
    raw = bytes(value[pos + 4:pos + 4 + n])
    if raw[-1:] != b"\0":
        raise ParamError("a string without its terminating NUL")
    try:
        return raw[:-1].decode(), pos + 4 + n
    except UnicodeDecodeError as exc:
        raise ParamError(f"a string that is not UTF-8 ({exc.reason})") from None


def decode_strings(value: memoryview, little: bool) -> List[str]:
    """A sequence of strings (PID_PARTITION)."""
    _need(value, 4, "a string sequence")
    (count,) = struct.unpack_from("<I" if little else ">I", value)
    if count > len(value) // 5:
        raise ParamError(f"a sequence of {count} strings in {len(value)} bytes")
    out, pos = [], 4
    for _ in range(count):
        pos += -pos % 4
        text, pos = _string_at(value, pos, little)
        out.append(text)
    return out


def decode_octets(value: memoryview, little: bool) -> bytes:
    """An octet sequence (USER_DATA, TOPIC_DATA, GROUP_DATA)."""
    _need(value, 4, "an octet sequence")
    (n,) = struct.unpack_from("<I" if little else ">I", value)
    if 4 + n > len(value):
        raise ParamError(f"an octet sequence of {n} bytes in {len(value) - 4}")
    return bytes(value[4:4 + n])


def decode_guid(value: memoryview) -> bytes:
    _need(value, 16, "a GUID")
    return bytes(value[:16])


def decode_locator(value: memoryview, little: bool) -> Locator:
    _need(value, 24, "a locator")
    kind, port = struct.unpack_from("<iI" if little else ">iI", value)
    return Locator(kind, port, bytes(value[8:24]))


def decode_shorts(value: memoryview, little: bool) -> List[int]:
    """A sequence of int16 (PID_DATA_REPRESENTATION)."""
    _need(value, 4, "a short sequence")
    (count,) = struct.unpack_from("<I" if little else ">I", value)
    if 4 + 2 * count > len(value):
        raise ParamError(f"a sequence of {count} shorts in {len(value) - 4} bytes")
    return list(struct.unpack_from(("<" if little else ">") + "h" * count, value, 4))


def shorts_bytes(values: Sequence[int]) -> bytes:
    return struct.pack("<I" + "h" * len(values), len(values), *values)


def strings_bytes(values: Iterable[str]) -> bytes:
    items = list(values)
    out = bytearray(struct.pack("<I", len(items)))
    for text in items:
        out += b"\0" * (-len(out) % 4)
        out += string_bytes(text)
    return bytes(out)


def sample_identity(guid: bytes, sn: int) -> bytes:
    """A SampleIdentity (DDS-RPC): the writer's GUID and a sequence number (high, low)."""
    return bytes(guid) + struct.pack("<iI", sn >> 32, sn & 0xFFFFFFFF)


def decode_sample_identity(value: memoryview, little: bool) -> Optional[Tuple[bytes, int]]:
    """(GUID, sequence number) of a SampleIdentity, or None when it is too short."""
    if len(value) < 24:
        return None
    hi, lo = struct.unpack_from("<iI" if little else ">iI", value, 16)
    return bytes(value[:16]), (hi << 32) | lo


def find(inline_qos: Optional[bytes], little: bool, pid: int) -> Optional[memoryview]:
    """The value of ``pid`` in an inline QoS list (raw, without sentinel), or None."""
    if not inline_qos:
        return None
    try:
        for key, value in parse_params(memoryview(inline_qos + b"\x01\x00\x00\x00"
                                                  if little else
                                                  inline_qos + b"\x00\x01\x00\x00"), little):
            if key == pid:
                return value
    except ParamError:
        return None
    return None


def status_info(inline_qos: Optional[bytes], little: bool) -> int:
    """PID_STATUS_INFO's flags (1 disposed, 2 unregistered), 0 when absent."""
    value = find(inline_qos, little, PID_STATUS_INFO)
    return value[3] if value is not None and len(value) >= 4 else 0
