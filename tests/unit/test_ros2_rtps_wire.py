"""RTPS's wire without sockets: datagrams captured from Fast DDS (Jazzy, Kilted) and Cyclone
(scripts/rtps_vectors.py, checked against what Wireshark's RTPS dissector says about each),
the builders, parameter lists and discovery data, and hypothesis on every parser a peer feeds.
"""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from minros.ros2.rtps import discovery as d
from minros.ros2.rtps import guid as g
from minros.ros2.rtps import messages as m
from minros.ros2.rtps import params as p

VECTORS = json.loads((Path(__file__).parent / "data" / "rtps_vectors.json").read_text())


def raw(vector: dict) -> bytes:
    """A vector's datagram; a fragment's bytes beyond the first 2 KB were not kept (zeros)."""
    return bytes.fromhex(vector["hex"]).ljust(vector["length"], b"\0")


def vector(source: str, kind: str) -> dict:
    for v in VECTORS:
        if v["source"].startswith(source) and v["kind"] == kind:
            return v
    raise LookupError((source, kind))


def ident(v: dict) -> str:
    return f"{v['source'].split(' (')[0].split(' 11')[0]}-{v['source'][10:16]}-{v['kind']}"


@pytest.mark.parametrize("v", VECTORS, ids=ident)
def test_every_captured_datagram_parses_as_wireshark_reads_it(v):
    msg = m.parse_message(raw(v))
    shark = v["tshark"]
    assert msg.vendor.hex() == shark["rtps.vendorId"][0][2:]
    assert msg.prefix.hex() == shark["rtps.guidPrefix.src"][0]
    cut = len(v["hex"]) // 2 < v["length"]  # a fragment kept in part: compare up to it

    def same(ours: list, theirs: list) -> None:
        assert ours == (theirs[:len(ours)] if cut else theirs)
    same([f"0x{s.kind:02x}" for s in msg.submessages],
         [x for x in shark["rtps.sm.id"] if int(x, 16) < 0x80 and x != "0x01"])
    assert msg.error is None
    writers = [s.writer_id.hex() for s in msg.submessages if hasattr(s, "writer_id")]
    same(writers, [w[2:] for w in shark["rtps.sm.wrEntityId"]])
    readers = [s.reader_id.hex() for s in msg.submessages if hasattr(s, "reader_id")]
    same(readers, [r[2:] for r in shark["rtps.sm.rdEntityId"]])
    numbers = []
    for s in msg.submessages:
        if isinstance(s, m.Heartbeat):
            numbers += [s.first, s.last]
        elif isinstance(s, (m.Data, m.DataFrag, m.NackFrag, m.HeartbeatFrag)):
            numbers.append(s.sn)
        elif isinstance(s, m.AckNack):
            numbers.append(s.base)
        elif isinstance(s, m.Gap):
            numbers += [s.start, s.list_base]
    same(numbers, [int(x) for x in shark.get("rtps.sm.seqNumber", [])])
    frags = [s for s in msg.submessages if isinstance(s, m.DataFrag)]
    if frags:
        f = frags[0]
        assert (f.start, f.count, f.fragment_size, f.sample_size) == (
            int(shark["rtps.data_frag.number"][0]), int(shark["rtps.data_frag.num_fragments"][0]),
            int(shark["rtps.data_frag.size"][0]), int(shark["rtps.data_frag.sample_size"][0]))
        assert len(f.payload) == min(f.count * f.fragment_size, f.sample_size)
    counts = [s.count for s in msg.submessages if isinstance(s, m.AckNack)]
    assert counts == [int(x) for x in shark.get("rtps.acknack.count", [])]
    nack_frags = [s for s in msg.submessages if isinstance(s, m.NackFrag)]
    assert [s.count for s in nack_frags] == [int(x) for x in shark.get("rtps.nack_frag.count", [])]
    assert [s.base for s in nack_frags] == [int(x) for x in
                                            shark.get("rtps.fragment_number.base32", [])]


@pytest.mark.parametrize("v", [v for v in VECTORS if v["kind"] == "spdp"], ids=ident)
def test_participant_data_of_each_vendor(v):
    msg = m.parse_message(raw(v))
    datas = [s for s in msg.submessages if isinstance(s, m.Data) and s.writer_id == g.SPDP_WRITER]
    shark = v["tshark"]
    ports = []
    for sub in datas:
        data = d.decode_participant(sub.payload)
        assert data.prefix == msg.prefix
        assert data.vendor == msg.vendor
        for loc in (data.metatraffic_unicast + data.metatraffic_multicast + data.default_unicast
                    + data.default_multicast):
            ports.append(loc.port)
        assert data.builtin_endpoints == int(shark["rtps.param.builtin_endpoint_set"][0], 16)
    assert sorted(set(ports)) == sorted({int(x) for x in shark["rtps.locator.port"]})
    if "rtps.param.userData" in shark:
        assert d.decode_participant(datas[0].payload).user_data.hex() == \
            shark["rtps.param.userData"][0]


def test_fast_dds_participant_data_in_detail():
    data = d.decode_participant(_only(vector("Fast DDS (jazzy", "spdp"), m.Data).payload)
    assert data.version == (2, 2) and data.vendor == g.VENDOR_FASTDDS
    assert data.lease_duration == 20.0
    assert [str(x) for x in data.metatraffic_unicast] == ["udpv4:127.0.0.1:7410"]
    assert not data.metatraffic_multicast  # Fast DDS listens on 7400 without saying so
    # rmw_fastrtps writes the enclave with its NUL (snprintf's length + 1)
    assert data.user_data == b"enclave=/;\0"
    assert d.user_data_value(data.user_data, "enclave") == "/"
    # Fast DDS's own parameters (0x8007 ...) are kept, not read
    assert any(pid == 0x8007 for pid, _ in data.vendor_params)
    kilted = d.decode_participant(_only(vector("Fast DDS (kilted", "spdp"), m.Data).payload)
    assert kilted.version == (2, 2)  # Fast DDS 3.2 too


def _only(v: dict, cls: type):
    subs = [s for s in m.parse_message(raw(v)).submessages if isinstance(s, cls)]
    assert subs, (v["kind"], cls)
    return subs[0]


@pytest.mark.parametrize("source", ["Fast DDS (jazzy", "Fast DDS (kilted", "Cyclone"])
def test_publication_data_of_each_vendor(source):
    v = vector(source, "sedp_publication")
    msg = m.parse_message(raw(v))
    topics = []
    for sub in msg.submessages:
        if isinstance(sub, m.Data) and sub.writer_id == g.SEDP_PUBLICATIONS_WRITER:
            data = d.decode_endpoint(sub.payload, msg.vendor)
            topics.append(data.topic)
            assert data.type_name in v["tshark"]["rtps.param.typeName"]
            assert not data.is_reader and data.guid[:12] == msg.prefix
            assert data.qos.reliability in (d.RELIABLE, d.BEST_EFFORT)
            if data.topic.startswith("rt/") and source.startswith("Fast DDS"):
                # rmw's; cyclonedds-python is plain DDS, without it
                assert data.user_data_value("typehash").startswith("RIHS01_")
    assert topics and set(topics) <= set(v["tshark"]["rtps.param.topicName"])


def test_fast_dds_request_and_reply_carry_their_identity_inline():
    request = _only(vector("Fast DDS (jazzy", "request"), m.Data)
    little = bool(request.flags & 1)
    # the client's reply reader, sequence number unknown: the standard PID and Fast DDS's own
    ident = p.decode_sample_identity(p.find(bytes(request.inline_qos), little,
                                            p.PID_RELATED_SAMPLE_IDENTITY), little)
    assert ident is not None and g.is_reader(ident[0][12:]) and ident[1] == m.SN_UNKNOWN
    assert p.find(bytes(request.inline_qos), little, 0x800F) is not None
    assert bytes(request.payload[:5]) == b"\x00\x01\x00\x00\x01"  # SetBool(data=True)
    reply = _only(vector("Fast DDS (jazzy", "reply"), m.Data)
    answered = p.decode_sample_identity(p.find(bytes(reply.inline_qos), True,
                                               p.PID_RELATED_SAMPLE_IDENTITY), True)
    assert answered == (ident[0], request.sn)


def test_user_data_is_plain_cdr_and_discovery_info_decodes():
    from minros.ros2.rmw.graph import decode_participant_info

    data = _only(vector("Fast DDS (jazzy", "user_data"), m.Data)
    payload = bytes(data.payload)
    assert payload[:4] == b"\x00\x01\x00\x00"
    (n,) = struct.unpack_from("<I", payload, 4)
    assert payload[8:8 + n - 1].decode().startswith("hello ")
    for distro in ("jazzy", "kilted"):
        msg = m.parse_message(raw(vector(f"Fast DDS ({distro}", "discovery_info")))
        info = [s for s in msg.submessages if isinstance(s, m.Data)][0]
        gid, nodes = decode_participant_info(bytes(info.payload))
        assert gid[:12] == msg.prefix and gid[12:] == g.ENTITYID_PARTICIPANT
        assert {n.name for n in nodes} <= {"pub", "sub"} and nodes
        assert all(len(x) == 16 for n in nodes for x in n.readers + n.writers)


def test_cyclone_fragments_several_per_datagram_then_heartbeat_frag():
    msg = m.parse_message(raw(vector("Cyclone", "data_frag")))
    frag = [s for s in msg.submessages if isinstance(s, m.DataFrag)][0]
    assert (frag.start, frag.count, frag.fragment_size) == (1, 10, 1344)
    hbf = [s for s in msg.submessages if isinstance(s, m.HeartbeatFrag)]
    assert hbf and hbf[0].sn == frag.sn and hbf[0].last_fragment == 10


def test_fast_dds_asks_for_a_withheld_fragment():
    msg = m.parse_message(raw(vector("Fast DDS (jazzy", "nack_frag")))
    nack = [s for s in msg.submessages if isinstance(s, m.NackFrag)][0]
    ack = [s for s in msg.submessages if isinstance(s, m.AckNack)][0]
    assert nack.missing == (2,)  # the one minros did not send (scripts/rtps_vectors.py)
    # ... and its ACKNACK leaves the half-received sample out of the set
    assert ack.base == nack.sn and ack.missing == ()


# -- builders ----------------------------------------------------------------------------------

PREFIX = bytes(range(1, 13))
RID = bytes.fromhex("00001204")
WID = bytes.fromhex("00001103")


def test_builders_round_trip():
    head, pad = m.data(RID, WID, 7, 5, b"", False)
    dgram = (m.header(PREFIX) + m.info_dst(bytes(12, )[:0] + bytes(range(20, 32)))
             + m.info_ts(1_700_000_000_123_456_789) + head + b"\x00\x01\x00\x00x" + pad
             + m.heartbeat(RID, WID, 3, 9, 42, final=True)
             + m.acknack(RID, WID, 5, [5, 7, 260], 3)
             + m.gap(RID, WID, 2, 5, [6, 8])
             + m.nack_frag(RID, WID, 9, 2, [2, 3, 40], 4)
             + m.heartbeat_frag(RID, WID, 9, 12, 5))
    qos = p.ParamWriter().add(p.PID_RELATED_SAMPLE_IDENTITY, p.sample_identity(b"g" * 16, 3))
    fhead, fpad = m.data_frag(RID, WID, 9, 2, 1, 1000, 2500, 1000, qos.encode())
    dgram += fhead + b"f" * 1000 + fpad
    msg = m.parse_message(dgram)
    assert msg.error is None and msg.prefix == PREFIX and msg.vendor == g.VENDOR_MINROS
    kinds = [type(s).__name__ for s in msg.submessages]
    assert kinds == ["InfoDst", "InfoTs", "Data", "Heartbeat", "AckNack", "Gap", "NackFrag",
                     "HeartbeatFrag", "DataFrag"]
    data, hb, ack, gap, nack, hbf, frag = msg.submessages[2:]
    assert data.dst == bytes(range(20, 32)) and abs(data.timestamp - 1_700_000_000_123_456_789) < 2
    # the payload runs to the submessage's end: its padding too (the encapsulation options
    # do not count it here, as in Fast DDS's samples)
    assert (data.sn, bytes(data.payload), data.key) == (7, b"\x00\x01\x00\x00x\0\0\0", False)
    assert (hb.first, hb.last, hb.count, hb.final) == (3, 9, 42, True)
    assert (ack.base, ack.missing, ack.count, ack.final) == (5, (5, 7, 260), 3, False)
    assert (gap.start, gap.list_base, gap.members) == (2, 5, (6, 8))
    assert gap.irrelevant() == [2, 3, 4, 6, 8]
    assert (nack.sn, nack.base, nack.missing, nack.count) == (9, 2, (2, 3, 40), 4)
    assert (hbf.sn, hbf.last_fragment) == (9, 12)
    assert (frag.start, frag.count, frag.fragment_size, frag.sample_size, frag.total) == \
        (2, 1, 1000, 2500, 3)
    assert bytes(frag.payload) == b"f" * 1000
    ident = p.decode_sample_identity(p.find(bytes(frag.inline_qos), True,
                                            p.PID_RELATED_SAMPLE_IDENTITY), True)
    assert ident == (b"g" * 16, 3)


def test_big_endian_submessages_parse_too():
    body = struct.pack(">4s4siIiIi", RID, WID, 0, 1, 0, 4, 7)
    msg = m.parse_message(m.header(PREFIX) + bytes((m.HEARTBEAT, 0x00)) + struct.pack(">H", 28)
                          + body)
    hb = msg.submessages[0]
    assert (hb.first, hb.last, hb.count) == (1, 4, 7)


def test_sets_are_bounded_both_ways():
    with pytest.raises(ValueError):
        m.acknack(RID, WID, 1, [1, 300], 1)  # beyond 256 bits of a set
    bad = m.header(PREFIX) + bytes((m.ACKNACK, 1)) + struct.pack("<H", 24) + RID + WID + \
        struct.pack("<iII", 0, 1, 100000) + struct.pack("<i", 1)
    msg = m.parse_message(bad)
    assert msg.submessages == [] and "256" in msg.error


@pytest.mark.parametrize("blob, reason", [
    (b"RTPX" + bytes(16), "not an RTPS message"),
    (b"RTPS" + bytes(8), "shorter than an RTPS header"),
    (b"RTPS\x01\x00" + bytes(14), "only 2.x"),
])
def test_bad_headers_are_typed_errors(blob, reason):
    with pytest.raises(m.MalformedMessage, match=reason):
        m.parse_message(blob)


def test_a_bad_submessage_keeps_what_came_before():
    good = m.heartbeat(RID, WID, 1, 2, 1)
    lying = bytes((m.DATA, 1)) + struct.pack("<H", 60000) + bytes(20)
    msg = m.parse_message(m.header(PREFIX) + good + lying)
    assert [type(s).__name__ for s in msg.submessages] == ["Heartbeat"]
    assert "announces 60000 bytes" in msg.error


def test_a_data_frag_cannot_claim_fragments_beyond_its_sample():
    head, _ = m.data_frag(RID, WID, 1, 5, 1, 100, 300, 100)
    msg = m.parse_message(m.header(PREFIX) + head + bytes(100))
    assert msg.submessages == [] and "beyond" in msg.error


# -- parameter lists and discovery -------------------------------------------------------------

def test_participant_data_round_trip():
    data = d.ParticipantData(
        prefix=PREFIX, domain_id=3, lease_duration=20.0,
        metatraffic_unicast=[p.Locator.udpv4("127.0.0.1", 8160)],
        metatraffic_multicast=[p.Locator.udpv4("239.255.0.1", 8150)],
        default_unicast=[p.Locator.udpv4("127.0.0.1", 8161)], user_data=b"enclave=/;")
    back = d.decode_participant(memoryview(d.encode_participant(data)))
    assert back == data


def test_endpoint_data_round_trip_and_reader_defaults():
    qos = d.Qos(reliability=d.BEST_EFFORT, durability=d.TRANSIENT_LOCAL, history=d.KEEP_LAST,
                depth=7, deadline=0.5, lifespan=2.25, partitions=("a", "b"),
                data_representation=(d.XCDR1,))
    data = d.EndpointData(PREFIX + bytes.fromhex("00000204"), "rt/x", "pkg::msg::dds_::X_", qos,
                          unicast=[p.Locator.udpv4("127.0.0.1", 7411)],
                          user_data=b"typehash=RIHS01_00;", vendor=g.VENDOR_MINROS)
    back = d.decode_endpoint(memoryview(d.encode_endpoint(data, PREFIX + g.ENTITYID_PARTICIPANT)))
    assert back == data
    # a reader that says nothing about reliability requested BEST_EFFORT (RTPS table 9.12)
    bare = b"\x00\x03\x00\x00" + (p.ParamWriter().add(p.PID_ENDPOINT_GUID, data.guid)
                                  .string(p.PID_TOPIC_NAME, "t").string(p.PID_TYPE_NAME, "T")
                                  .encode())
    assert d.decode_endpoint(memoryview(bare)).qos.reliability == d.BEST_EFFORT
    writer = PREFIX + bytes.fromhex("00000203")
    bare_writer = b"\x00\x03\x00\x00" + (p.ParamWriter().add(p.PID_ENDPOINT_GUID, writer)
                                         .string(p.PID_TOPIC_NAME, "t")
                                         .string(p.PID_TYPE_NAME, "T").encode())
    assert d.decode_endpoint(memoryview(bare_writer)).qos.reliability == d.RELIABLE


@pytest.mark.parametrize("offered, requested, reason", [
    (d.Qos(reliability=d.BEST_EFFORT), d.Qos(reliability=d.RELIABLE), "reliability"),
    (d.Qos(), d.Qos(durability=d.TRANSIENT_LOCAL), "durability"),
    (d.Qos(deadline=2.0), d.Qos(deadline=1.0), "deadline"),
    (d.Qos(liveliness=d.AUTOMATIC), d.Qos(liveliness=d.MANUAL_BY_TOPIC), "liveliness"),
    (d.Qos(lease_duration=5.0), d.Qos(lease_duration=1.0), "liveliness lease"),
    (d.Qos(partitions=("a",)), d.Qos(partitions=("b",)), "partitions"),
    (d.Qos(data_representation=(d.XCDR2,)), d.Qos(), "data representation"),
    (d.Qos(), d.Qos(reliability=d.BEST_EFFORT), None),
    (d.Qos(durability=d.TRANSIENT_LOCAL), d.Qos(), None),
    (d.Qos(deadline=1.0), d.Qos(deadline=math.inf), None),
    (d.Qos(partitions=("cam*",)), d.Qos(partitions=("camera",)), None),
])
def test_qos_request_offer_rules(offered, requested, reason):
    result = d.incompatibility(offered, requested)
    if reason is None:
        assert result is None
    else:
        assert result is not None and result.startswith(reason + ":")


def test_ports_follow_the_spec_mapping():
    assert d.metatraffic_multicast_port(0) == 7400
    assert (d.metatraffic_unicast_port(0, 0), d.user_unicast_port(0, 0)) == (7410, 7411)
    assert (d.metatraffic_unicast_port(1, 3), d.user_unicast_port(1, 3)) == (7666, 7667)


def test_durations_round_trip_and_infinity():
    for value in (0.0, 0.1, 20.0, 1234.5):
        assert abs(p.decode_duration(memoryview(p.duration_bytes(value)), True) - value) < 1e-9
    assert p.decode_duration(memoryview(p.duration_bytes(math.inf)), True) == math.inf


# -- hypothesis: whatever a peer sends ----------------------------------------------------------

SAMPLES = [raw(v) for v in VECTORS if len(v["hex"]) // 2 == v["length"]]


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.binary(max_size=600))
def test_any_bytes_are_a_message_or_a_typed_error(blob):
    try:
        msg = m.parse_message(b"RTPS\x02\x04" + bytes(14) + blob)
    except m.MalformedMessage:
        return
    for sub in msg.submessages:
        for name in ("missing", "members"):
            assert len(getattr(sub, name, ())) <= m.MAX_SET_BITS


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(SAMPLES), st.data())
def test_mutated_captures_are_a_message_or_a_typed_error(sample, data):
    buf = bytearray(sample)
    for _ in range(data.draw(st.integers(1, 8))):
        i = data.draw(st.integers(0, len(buf) - 1))
        buf[i] = data.draw(st.integers(0, 255))
    cut = data.draw(st.integers(0, len(buf)))
    try:
        msg = m.parse_message(bytes(buf[:cut]))
    except m.MalformedMessage:
        return
    for sub in msg.submessages:
        payload = getattr(sub, "payload", None)
        if isinstance(sub, m.Data) and payload is not None:
            try:
                if sub.writer_id == g.SPDP_WRITER:
                    d.decode_participant(payload)
                elif sub.writer_id in (g.SEDP_PUBLICATIONS_WRITER, g.SEDP_SUBSCRIPTIONS_WRITER):
                    d.decode_endpoint(payload)
            except d.DiscoveryError:
                pass
        if sub.inline_qos is not None if hasattr(sub, "inline_qos") else False:
            p.find(bytes(sub.inline_qos), True, p.PID_RELATED_SAMPLE_IDENTITY)


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=300))
def test_any_discovery_payload_is_data_or_a_typed_error(blob):
    for payload in (b"\x00\x03\x00\x00" + blob, blob):
        for decode in (d.decode_participant, d.decode_endpoint):
            try:
                decode(memoryview(payload))
            except d.DiscoveryError:
                pass


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=300))
def test_any_discovery_info_is_nodes_or_a_typed_error(blob):
    from minros.ros2.rmw.graph import GraphError, decode_participant_info

    try:
        decode_participant_info(b"\x00\x01\x00\x00" + blob)
    except GraphError:
        pass
