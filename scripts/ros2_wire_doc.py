#!/usr/bin/env python3
"""The excerpts of docs/ros2.md's wire part: datagrams captured from real peers
(tests/unit/data/rtps_vectors.json, made by scripts/rtps_vectors.py), laid out byte by byte
with minros's own parser, so the page teaches from what Fast DDS and Cyclone send.

    .venv/bin/python scripts/ros2_wire_doc.py            # print every excerpt
    .venv/bin/python scripts/ros2_wire_doc.py --write    # rewrite them in docs/ros2.md

tests/unit/test_ros2_wire_doc.py fails when the page and this script disagree.
"""

from __future__ import annotations

import json
import re
import struct
import sys
from pathlib import Path
from typing import Callable, Dict, List

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "src"))

from minros.ros2.rtps import guid as g  # noqa: E402
from minros.ros2.rtps import messages as m  # noqa: E402
from minros.ros2.rtps import params as p  # noqa: E402

DOC = REPO / "docs" / "ros2.md"
VECTORS = json.loads((REPO / "tests" / "unit" / "data" / "rtps_vectors.json").read_text())

NAMES = {m.PAD: "PAD", m.ACKNACK: "ACKNACK", m.HEARTBEAT: "HEARTBEAT", m.GAP: "GAP",
         m.INFO_TS: "INFO_TS", m.INFO_SRC: "INFO_SRC", m.INFO_DST: "INFO_DST",
         m.NACK_FRAG: "NACK_FRAG", m.HEARTBEAT_FRAG: "HEARTBEAT_FRAG", m.DATA: "DATA",
         m.DATA_FRAG: "DATA_FRAG"}
PIDS = {v: k for k, v in vars(p).items() if k.startswith("PID_") and isinstance(v, int)}
ENTITIES = {g.SPDP_WRITER: "SPDP writer", g.SPDP_READER: "SPDP reader",
            g.SEDP_PUBLICATIONS_WRITER: "SEDP publications writer",
            g.SEDP_PUBLICATIONS_READER: "SEDP publications reader",
            g.SEDP_SUBSCRIPTIONS_WRITER: "SEDP subscriptions writer",
            g.SEDP_SUBSCRIPTIONS_READER: "SEDP subscriptions reader",
            bytes.fromhex("000200c2"): "liveliness writer",
            bytes.fromhex("000200c7"): "liveliness reader",
            g.ENTITYID_UNKNOWN: "unknown: any reader"}


def vector(source: str, kind: str) -> bytes:
    for v in VECTORS:
        if v["source"].startswith(source) and v["kind"] == kind:
            return bytes.fromhex(v["hex"]).ljust(v["length"], b"\0")
    raise LookupError((source, kind))


def entity(e: bytes) -> str:
    if e in ENTITIES:
        return ENTITIES[e]
    kind = {0x02: "writer, keyed", 0x03: "writer", 0x04: "reader", 0x07: "reader, keyed"}
    return f"user {kind.get(e[3], hex(e[3]))} #{int.from_bytes(e[:3], 'big')}"


def hexs(b: bytes, limit: int = 24) -> str:
    h = b[:limit].hex()
    return h + ("…" if len(b) > limit else "")


def value_text(pid: int, value: bytes, little: bool) -> str:
    view = memoryview(value)
    try:
        if pid in (p.PID_TOPIC_NAME, p.PID_TYPE_NAME, p.PID_ENTITY_NAME):
            return repr(p.decode_string(view, little))
        if pid in (p.PID_USER_DATA, p.PID_TOPIC_DATA, p.PID_GROUP_DATA):
            return repr(p.decode_octets(view, little))
        if pid in (p.PID_UNICAST_LOCATOR, p.PID_MULTICAST_LOCATOR, p.PID_DEFAULT_UNICAST_LOCATOR,
                   p.PID_METATRAFFIC_UNICAST_LOCATOR, p.PID_METATRAFFIC_MULTICAST_LOCATOR,
                   p.PID_DEFAULT_MULTICAST_LOCATOR):
            return str(p.decode_locator(view, little))
        if pid == p.PID_PARTICIPANT_LEASE_DURATION:
            return f"{p.decode_duration(view, little):g} s"
        if pid == p.PID_RELIABILITY:
            kind = {1: "BEST_EFFORT", 2: "RELIABLE"}.get(p.decode_u32(view, little), "?")
            return f"{kind}, max_blocking_time {p.decode_duration(view[4:], little):g} s"
        if pid == p.PID_DURABILITY:
            return ["VOLATILE", "TRANSIENT_LOCAL", "TRANSIENT", "PERSISTENT"][
                p.decode_u32(view, little)]
        if pid == p.PID_BUILTIN_ENDPOINT_SET:
            return f"0x{p.decode_u32(view, little):08x}"
        if pid in (p.PID_PARTICIPANT_GUID, p.PID_ENDPOINT_GUID, p.PID_KEY_HASH):
            return g.guid_text(bytes(view[:16]))
        if pid == p.PID_RELATED_SAMPLE_IDENTITY:
            ident = p.decode_sample_identity(view, little)
            assert ident is not None
            sn = "unknown" if ident[1] == m.SN_UNKNOWN else str(ident[1])
            return f"{g.guid_text(ident[0])}, sequence number {sn}"
        if pid in (p.PID_PROTOCOL_VERSION,):
            return f"{value[0]}.{value[1]}"
        if pid == p.PID_VENDORID:
            return g.vendor_name(value[:2])
    except (p.ParamError, IndexError, struct.error):
        pass
    return hexs(value, 16)


def param_lines(plist: bytes, little: bool, indent: str) -> List[str]:
    out = []
    for pid, value in p.parse_params(memoryview(plist), little):
        name = PIDS.get(pid, f"0x{pid:04x} ({'vendor-specific' if pid & 0x8000 else '?'})")
        head = struct.pack("<HH" if little else ">HH", pid, len(value)).hex()
        out.append(f"{indent}{head} {name}: {value_text(pid, bytes(value), little)}")
    out.append(f"{indent}{'01000000' if little else '00010000'} PID_SENTINEL")
    return out


def layout(raw: bytes, *, params: bool = True, only: Callable[[m.Submessage], bool] = None,
           payload: Callable[[bytes], List[str]] = None) -> str:
    """A datagram laid out: the header, then each submessage with its fields."""
    msg = m.parse_message(raw)
    lines = [f"{raw[:4].hex()} {raw[4:6].hex()} {raw[6:8].hex()} {raw[8:20].hex()}"
             f"   RTPS {msg.version[0]}.{msg.version[1]}, {g.vendor_name(msg.vendor)}, "
             f"GUID prefix {g.guid_text(msg.prefix)}"]
    skipped = 0
    for sub in msg.submessages:
        if only is not None and not only(sub):
            skipped += 1
            continue
        if skipped:
            lines.append(f"  ({skipped} more submessages)")
            skipped = 0
        name = NAMES.get(sub.kind, hex(sub.kind))
        flags = f"flags {sub.flags:02x}"
        if isinstance(sub, m.InfoTs):
            lines.append(f"  {name:9} {flags}  source time {sub.time} ns")
        elif isinstance(sub, m.InfoDst):
            lines.append(f"  {name:9} {flags}  for participant {g.guid_text(sub.prefix)}")
        elif isinstance(sub, m.Data):
            what = "key" if sub.key else "data"
            lines.append(f"  {name:9} {flags}  {entity(sub.writer_id)} -> "
                         f"{entity(sub.reader_id)}, sequence number {sub.sn}")
            if sub.inline_qos is not None:
                lines.append("    inline QoS:")
                lines += param_lines(bytes(sub.inline_qos) + b"\x01\x00\x00\x00",
                                     bool(sub.flags & 1), "      ")
            if sub.payload is not None:
                body = bytes(sub.payload)
                lines.append(f"    serialized {what}: encapsulation {body[:4].hex()} "
                             f"({len(body)} bytes)")
                if body[:2] in (b"\x00\x03", b"\x00\x02") and params:
                    lines += param_lines(body[4:], body[1] == 3, "      ")
                elif payload is not None:
                    lines += ["      " + x for x in payload(body)]
                else:
                    lines.append(f"      {hexs(body[4:], 32)}")
        elif isinstance(sub, m.DataFrag):
            lines.append(f"  {name:9} {flags}  {entity(sub.writer_id)} -> "
                         f"{entity(sub.reader_id)}, sequence number {sub.sn}: fragment "
                         f"{sub.start} (+{sub.count - 1}) of {sub.total}, {sub.fragment_size} "
                         f"bytes each, sample {sub.sample_size} bytes")
        elif isinstance(sub, m.Heartbeat):
            final = ", final" if sub.final else ""
            lines.append(f"  {name:9} {flags}  {entity(sub.writer_id)} -> "
                         f"{entity(sub.reader_id)}: has {sub.first}..{sub.last}, count "
                         f"{sub.count}{final}")
        elif isinstance(sub, m.AckNack):
            missing = ", ".join(map(str, sub.missing)) or "nothing"
            lines.append(f"  {name:9} {flags}  {entity(sub.reader_id)} -> "
                         f"{entity(sub.writer_id)}: has all before {sub.base}, misses "
                         f"{missing}, count {sub.count}")
        elif isinstance(sub, m.NackFrag):
            lines.append(f"  {name:9} {flags}  {entity(sub.reader_id)} -> "
                         f"{entity(sub.writer_id)}: of {sub.sn} misses fragments "
                         f"{', '.join(map(str, sub.missing))}, count {sub.count}")
        elif isinstance(sub, m.HeartbeatFrag):
            lines.append(f"  {name:9} {flags}  {entity(sub.writer_id)}: sent fragments "
                         f"1..{sub.last_fragment} of {sub.sn}")
        elif isinstance(sub, m.Gap):
            lines.append(f"  {name:9} {flags}  irrelevant: {sub.irrelevant()}")
        else:
            lines.append(f"  {name:9} {flags}")
    if skipped:
        lines.append(f"  ({skipped} more submessages)")
    for sid in vendor_submessages(raw):
        lines.append(f"  0x{sid:02x}      (vendor-specific: skipped; Fast DDS's statistics)")
    return "\n".join(lines)


def vendor_submessages(raw: bytes) -> List[int]:
    """Ids 0x80 and up among a datagram's submessage headers (the parser skips them)."""
    out, pos = [], m.HEADER_SIZE
    while pos + 4 <= len(raw):
        sid, flags = raw[pos], raw[pos + 1]
        (length,) = struct.unpack_from("<H" if flags & 1 else ">H", raw, pos + 2)
        if sid >= 0x80:
            out.append(sid)
        if length == 0 and sid not in (m.PAD, m.INFO_TS):
            break
        pos += 4 + length
    return out


def string_payload(body: bytes) -> List[str]:
    (n,) = struct.unpack_from("<I", body, 4)
    return [f"{body[4:8].hex()} {body[8:8 + n].hex()}   std_msgs/String: "
            f"{body[8:7 + n].decode()!r}"]


def setbool_payload(body: bytes) -> List[str]:
    return [f"{body[4:].hex()}   std_srvs/SetBool: data={bool(body[4])} (then padding)"]


def reply_payload(body: bytes) -> List[str]:
    (n,) = struct.unpack_from("<I", body, 8)
    return [f"{body[4:8].hex()} {body[8:12].hex()} {body[12:12 + n].hex()}   "
            f"success={bool(body[4])}, message={body[12:11 + n].decode()!r}"]


def cdds_request(body: bytes) -> List[str]:
    guid, seq = struct.unpack_from("<Qq", body, 4)
    return [f"{body[4:12].hex()} {body[12:20].hex()}   cdds_request_header_t: client "
            f"{guid:#x}, request {seq}", f"{body[20:].hex()}   std_srvs/SetBool: "
            f"data={bool(body[20])} (then padding)"]


def cdds_reply(body: bytes) -> List[str]:
    guid, seq = struct.unpack_from("<Qq", body, 4)
    (n,) = struct.unpack_from("<I", body, 24)
    return [f"{body[4:12].hex()} {body[12:20].hex()}   the same header: client {guid:#x}, "
            f"request {seq}", f"{body[20:24].hex()} {body[24:28].hex()} "
            f"{body[28:28 + n].hex()}   success={bool(body[20])}, "
            f"message={body[28:27 + n].decode()!r}"]


def discovery_info(body: bytes) -> List[str]:
    from minros.ros2.rmw.graph import decode_participant_info

    gid, nodes = decode_participant_info(body)
    out = [f"{body[4:20].hex()}   gid: the participant's GUID"]
    for node in nodes:
        out.append(f"node {node.namespace!r} {node.name!r}: {len(node.readers)} reader gids, "
                   f"{len(node.writers)} writer gids")
        for x in node.writers[:2]:
            out.append(f"  writer {g.guid_text(x)}")
        if len(node.writers) > 2:
            out.append("  ...")
    return out


def excerpts() -> Dict[str, str]:
    is_sedp = lambda s: not isinstance(s, m.Data) or (  # noqa: E731
        s.writer_id != g.SEDP_PUBLICATIONS_WRITER or s.payload is None
        or b"rt/chatter" in bytes(s.payload))
    return {
        "spdp-fastdds": layout(vector("Fast DDS (jazzy", "spdp")),
        "spdp-cyclone": layout(vector("Cyclone", "spdp"), only=lambda s: s.dst is None),
        "spdp-minros": layout(vector("minros", "spdp")),
        "sedp-fastdds": layout(vector("Fast DDS (jazzy", "sedp_publication"), only=is_sedp),
        "data-fastdds": layout(vector("Fast DDS (jazzy", "user_data"), payload=string_payload),
        "heartbeat-acknack": "\n".join([
            layout(vector("Fast DDS (jazzy", "heartbeat")),
            layout(vector("Fast DDS (jazzy", "acknack"))]),
        "cyclone-heartbeats": layout(vector("Cyclone", "heartbeat")),
        "frag-fastdds": layout(vector("Fast DDS (jazzy", "data_frag")),
        "frag-minros": layout(vector("minros", "data_frag")),
        "nackfrag-fastdds": layout(vector("Fast DDS (jazzy", "nack_frag")),
        "frag-cyclone": layout(vector("Cyclone", "data_frag")),
        "discovery-info": layout(vector("Fast DDS (jazzy", "discovery_info"),
                                 payload=discovery_info),
        "request-fastdds": layout(vector("Fast DDS (jazzy", "request"), payload=setbool_payload),
        "reply-fastdds": layout(vector("Fast DDS (jazzy", "reply"), payload=reply_payload),
        "request-cyclone": layout(vector("Cyclone", "request"), payload=cdds_request),
        "reply-minros-cyclone": layout(vector("minros (to Cyclone)", "reply"),
                                       payload=cdds_reply),
    }


BLOCK = re.compile(r"(<!-- rtps: (?P<name>[\w-]+) -->\n```text\n)(?P<body>.*?)^```$",
                   re.S | re.M)


def render(doc: str) -> str:
    texts = excerpts()
    return BLOCK.sub(lambda mt: mt.group(1) + texts[mt.group("name")] + "\n```", doc)


def main() -> None:
    if "--write" in sys.argv:
        DOC.write_text(render(DOC.read_text()))
        return
    for name, text in excerpts().items():
        print(f"<!-- rtps: {name} -->\n```text\n{text}\n```\n")


if __name__ == "__main__":
    main()
