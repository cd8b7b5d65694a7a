"""GUIDs, entity ids and vendor ids: how RTPS names every participant, writer and reader.

A GUID is 16 bytes: a 12-byte *prefix* naming the participant and a 4-byte *entity id* naming
one endpoint in it (three bytes of key, one byte of kind). They are plain ``bytes`` here: cheap
to hash, to compare and to slice out of a datagram, which is what the hot path does with them.
"""

from __future__ import annotations

import os
from typing import Dict

__all__ = [
    "ENTITYID_PARTICIPANT", "ENTITYID_UNKNOWN", "GUID_UNKNOWN", "PREFIX_UNKNOWN",
    "SEDP_PUBLICATIONS_READER", "SEDP_PUBLICATIONS_WRITER", "SEDP_SUBSCRIPTIONS_READER",
    "SEDP_SUBSCRIPTIONS_WRITER", "SPDP_READER", "SPDP_WRITER", "VENDOR_CYCLONE",
    "VENDOR_FASTDDS", "VENDOR_MINROS", "entity_id", "guid", "guid_text", "is_reader",
    "is_writer", "keyed", "new_prefix", "vendor_name",
]

PREFIX_UNKNOWN = bytes(12)
ENTITYID_UNKNOWN = bytes(4)
GUID_UNKNOWN = bytes(16)
ENTITYID_PARTICIPANT = bytes.fromhex("000001c1")
# the built-in endpoints of discovery (RTPS 2.5 table 9.13)
SPDP_WRITER = bytes.fromhex("000100c2")
SPDP_READER = bytes.fromhex("000100c7")
SEDP_PUBLICATIONS_WRITER = bytes.fromhex("000003c2")
SEDP_PUBLICATIONS_READER = bytes.fromhex("000003c7")
SEDP_SUBSCRIPTIONS_WRITER = bytes.fromhex("000004c2")
SEDP_SUBSCRIPTIONS_READER = bytes.fromhex("000004c7")

# entity kinds (the id's last byte): user-defined writers and readers, with a key or not
KIND_WRITER_WITH_KEY = 0x02
KIND_WRITER_NO_KEY = 0x03
KIND_READER_NO_KEY = 0x04
KIND_READER_WITH_KEY = 0x07

#: minros's vendor id. The OMG assigns 0x01xx ids (0x0101 RTI ... 0x010f eProsima, 0x0110
#: Eclipse Cyclone, 0x0111 GurumNetworks, 0x0112 Atostek RustDDS, 0x0113 ZRDDS, 0x0114 Dust DDS,
#: 0x0120 PrismTech Vortex Cloud, in the DDS Foundation's list); minros has none assigned and
#: uses 0x016d ('m'), which that list leaves free. Peers treat an unknown vendor by the standard
#: alone (they ignore vendor-specific parameters from it), which is what minros asks for.
VENDOR_MINROS = b"\x01\x6d"
VENDOR_FASTDDS = b"\x01\x0f"
VENDOR_CYCLONE = b"\x01\x10"

_VENDORS: Dict[bytes, str] = {
    b"\x01\x01": "RTI Connext DDS", b"\x01\x02": "OpenSplice DDS", b"\x01\x03": "OpenDDS",
    b"\x01\x06": "CoreDX DDS", b"\x01\x0a": "RTI Connext Micro", VENDOR_FASTDDS: "Fast DDS",
    VENDOR_CYCLONE: "Cyclone DDS", b"\x01\x11": "GurumDDS", b"\x01\x12": "RustDDS",
    b"\x01\x13": "ZRDDS", b"\x01\x14": "Dust DDS", VENDOR_MINROS: "minros",
}


def vendor_name(vendor: bytes) -> str:
    """A vendor id as a name ("Fast DDS"), or its hex for one this table lacks."""
    return _VENDORS.get(bytes(vendor), f"vendor {bytes(vendor).hex()}")


def new_prefix(vendor: bytes = VENDOR_MINROS) -> bytes:
    """A fresh GUID prefix: the vendor id, then ten random bytes (unique without coordination;
    the spec only asks that no two participants share one)."""
    return bytes(vendor) + os.urandom(10)


def entity_id(key: int, kind: int) -> bytes:
    """The entity id of the ``key``-th endpoint of ``kind`` (``KIND_WRITER_NO_KEY``, ...)."""
    return key.to_bytes(3, "big") + bytes((kind,))


def guid(prefix: bytes, entity: bytes) -> bytes:
    return bytes(prefix) + bytes(entity)


def is_reader(entity: bytes) -> bool:
    """Readers' kinds have bit 0x04 (0x04, 0x07, 0xc4, 0xc7); writers' do not (0x02, 0x03, ...)."""
    return bool(entity[3] & 0x04)


def is_writer(entity: bytes) -> bool:
    return entity[3] & 0x3f in (0x02, 0x03)


def keyed(entity: bytes) -> bool:
    """Whether an endpoint's topic has a key (kinds 0x02 and 0x07, built-in or not)."""
    return entity[3] & 0x0f in (0x02, 0x07)


def guid_text(value: bytes) -> str:
    """A GUID as RTPS tools print it: ``010f7f01.eb7dca6d.00000000.000001c1``."""
    h = bytes(value).hex()
    return ".".join(h[i:i + 8] for i in range(0, len(h), 8))
