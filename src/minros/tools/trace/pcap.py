"""``minros trace pcap``: a libpcap capture file made from a trace, without root or tcpdump.

Each traced byte stream becomes a TCP connection between the real addresses and ports: a
three-way handshake before its first bytes, one segment per HTTP request or response,
connection header or frame (split at the IP size limit), FIN when a side closed, sequence and
acknowledgement numbers consistent with the stream offsets the trace recorded. What the trace
did not keep (the rest of a long frame, frames beyond ``MINROS_TRACE_FRAMES``) is left out
the way a capture with a short snap length leaves it out: a packet's captured length is what
the trace has, its original length what went on the wire, and frames never traced are a gap
in the sequence numbers. Packets are raw IPv4/IPv6 (LINKTYPE_RAW), timestamps the trace's.

Wireshark shows XML-RPC as HTTP (with its XML body); TCPROS needs its dissector switched on for
the TCPROS servers' ports (:func:`tshark_command` says why the heuristic alone is not enough).
"""

from __future__ import annotations

import hashlib
import ipaddress
import struct
from dataclasses import dataclass, field
from typing import BinaryIO, Dict, Iterable, List, Optional, Tuple

from minros.tools.trace.merge import Call, Item, Wire

__all__ = ["LINKTYPE_RAW", "build", "tshark_command", "write"]

LINKTYPE_RAW = 101
SNAPLEN = 262144
#: TCP payload per segment: IPv4's 65535-byte packet limit minus the two headers
MSS = 65535 - 40
_SYN, _FIN, _PSH, _ACK = 0x02, 0x01, 0x08, 0x10
_U32 = struct.Struct("<I")


@dataclass
class _Flow:
    """One direction of a TCP connection."""

    src: Tuple[str, int]
    dst: Tuple[str, int]
    isn: int
    sent: int = 0  # stream bytes sent so far (the next sequence number is isn + 1 + sent)
    fin: bool = False


@dataclass
class _Segment:
    t: float
    order: int
    flow: _Flow
    back: _Flow
    flags: int
    off: int = 0
    data: bytes = b""
    size: int = 0  # the payload's real length (>= len(data))


@dataclass
class _Builder:
    flows: Dict[Tuple[str, str], _Flow] = field(default_factory=dict)
    segments: List[_Segment] = field(default_factory=list)
    opened: set = field(default_factory=set)

    def flow(self, src: str, dst: str) -> Optional[_Flow]:
        key = (src, dst)
        found = self.flows.get(key)
        if found is None:
            a, b = _endpoint(src), _endpoint(dst)
            if a is None or b is None or _family(a[0]) != _family(b[0]):
                return None
            isn = int.from_bytes(hashlib.sha256(f"{src}>{dst}".encode()).digest()[:4], "big")
            found = self.flows[key] = _Flow(a, b, isn)
        return found

    def add(self, t: float, src: str, dst: str, flags: int, off: int = 0, data: bytes = b"",
            size: int = 0) -> None:
        flow, back = self.flow(src, dst), self.flow(dst, src)
        if flow is None or back is None:
            return
        self.segments.append(_Segment(t, len(self.segments), flow, back, flags, off, data, size))

    def handshake(self, t: float, client: str, server: str) -> None:
        if (client, server) in self.opened:
            return
        self.opened.add((client, server))
        self.add(t - 3e-6, client, server, _SYN)
        self.add(t - 2e-6, server, client, _SYN | _ACK)
        self.add(t - 1e-6, client, server, _ACK)


def _endpoint(text: str) -> Optional[Tuple[str, int]]:
    host, _sep, port = text.rpartition(":")
    host = host.strip("[]")
    if not port.isdigit():
        return None
    try:
        ipaddress.ip_address(host)
    except ValueError:
        return None
    return host, int(port)


def _family(host: str) -> int:
    return ipaddress.ip_address(host).version


def _header_bytes(fields: List[List[str]]) -> bytes:
    """A connection header in the traced field order (the codec sorts; peers need not)."""
    parts = []
    for key, value in fields:
        item = f"{key}={value}".encode()
        parts.append(_U32.pack(len(item)) + item)
    body = b"".join(parts)
    return _U32.pack(len(body)) + body


def _calls(builder: _Builder, calls: List[Call]) -> None:
    by_conn: Dict[Tuple[str, str], List[Call]] = {}
    for call in calls:
        if call.client and call.server and call.n:
            by_conn.setdefault((call.client, call.server), []).append(call)
    for (client, server), conn_calls in by_conn.items():
        conn_calls.sort(key=lambda c: c.n)
        up = down = 0  # stream offsets (a call missing from the trace shifts later ones)
        for call in conn_calls:
            if call.n == 1:
                builder.handshake(call.t, client, server)
            request = call.request.encode("utf-8")
            builder.add(call.t, client, server, _PSH | _ACK, up, request, call.request_len)
            up += call.request_len
            if call.response is not None:
                response = call.response.encode("utf-8")
                builder.add(call.t_reply, server, client, _PSH | _ACK, down, response,
                            call.response_len)
                down += call.response_len


def _wires(builder: _Builder, wires: List[Wire]) -> None:
    for item in wires:
        conn = item.conn
        client, server = conn.client, conn.server
        src, dst = (client, server) if item.dir == "c2s" else (server, client)
        if item.what == "open":
            builder.handshake(item.t, client, server)
        elif item.what == "header":
            data = _header_bytes(item.fields or [])
            builder.add(item.t, src, dst, _PSH | _ACK, item.off, data, item.len)
        elif item.what == "frame":
            if item.ok >= 0:
                prefix = bytes([item.ok]) + _U32.pack(item.len)
            else:
                prefix = _U32.pack(item.len)
            data = prefix + bytes.fromhex(item.head)
            builder.add(item.t, src, dst, _PSH | _ACK, item.off, data, len(prefix) + item.len)
        elif item.what == "data":
            builder.add(item.t, src, dst, _PSH | _ACK, item.off, bytes.fromhex(item.head), item.len)
        elif item.what in ("close", "eof"):
            stats = item.stats or {}
            side = stats.get("side")
            # close: this side's FIN; eof: the peer's FIN, as this side saw it
            mine = (client, server) if side == "connect" else (server, client)
            if item.what == "close":
                builder.add(item.t, mine[0], mine[1], _FIN | _ACK, int(stats.get("sent", 0)))
            else:
                builder.add(item.t, mine[1], mine[0], _FIN | _ACK, int(stats.get("received", 0)))


def _checksum(data: bytes) -> int:
    if len(data) % 2:
        data += b"\0"
    total = sum(struct.unpack(f"!{len(data) // 2}H", data))
    while total >> 16:
        total = (total & 0xFFFF) + (total >> 16)
    return ~total & 0xFFFF


def _packet(seg: _Segment, seq_off: int, data: bytes, size: int, ident: int) -> Tuple[bytes, int]:
    """(the captured bytes of one IP packet, its original length)."""
    flow, back = seg.flow, seg.back
    seq = (flow.isn + 1 + seq_off) & 0xFFFFFFFF if not seg.flags & _SYN else flow.isn
    ack = (back.isn + 1 + back.sent + (1 if back.fin else 0)) & 0xFFFFFFFF
    flags = seg.flags
    if flags == _SYN:
        ack = 0
    elif flags == _SYN | _ACK:
        ack = (back.isn + 1) & 0xFFFFFFFF
    tcp = struct.pack("!HHIIBBHHH", flow.src[1], flow.dst[1], seq, ack, 5 << 4, flags,
                      65535, 0, 0)
    src = ipaddress.ip_address(flow.src[0]).packed
    dst = ipaddress.ip_address(flow.dst[0]).packed
    length = len(tcp) + size
    if len(data) == size:  # whole: a real checksum over pseudo-header, header and payload
        if len(src) == 4:
            pseudo = src + dst + struct.pack("!BBH", 0, 6, length)
        else:
            pseudo = src + dst + struct.pack("!IxxxB", length, 6)
        csum = _checksum(pseudo + tcp + data)
        tcp = tcp[:16] + struct.pack("!H", csum) + tcp[18:]
    if len(src) == 4:
        ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + length, ident & 0xFFFF, 0x4000, 64, 6,
                         0, src, dst)
        ip = ip[:10] + struct.pack("!H", _checksum(ip)) + ip[12:]
    else:
        ip = struct.pack("!IHBB16s16s", 6 << 28, length, 6, 64, src, dst)
    return ip + tcp + data, len(ip) + length


def build(items: Iterable[Item]) -> Tuple[List[Tuple[float, bytes, int]], int, List[int]]:
    """The packets of ``items`` as (time, captured bytes, original length) in time order, the
    number of TCP connections, and the TCPROS servers' ports (for Wireshark's Decode As)."""
    builder = _Builder()
    items = list(items)
    _calls(builder, [item for item in items if isinstance(item, Call)])
    _wires(builder, [item for item in items if isinstance(item, Wire)])
    packets: List[Tuple[float, bytes, int]] = []
    ident = 0
    for seg in sorted(builder.segments, key=lambda s: (s.t, s.order)):
        flow = seg.flow
        if seg.flags & _FIN:
            if flow.fin:
                continue
            ident += 1
            packets.append((seg.t, *_packet(seg, seg.off, b"", 0, ident)))
            flow.sent = max(flow.sent, seg.off)
            flow.fin = True
            continue
        if seg.flags & _SYN:
            ident += 1
            packets.append((seg.t, *_packet(seg, 0, b"", 0, ident)))
            continue
        if not seg.size and seg.flags == _ACK:
            ident += 1
            packets.append((seg.t, *_packet(seg, 0, b"", 0, ident)))
            continue
        start = 0
        while start < seg.size:
            size = min(MSS, seg.size - start)
            data = seg.data[start:start + size]
            ident += 1
            packets.append((seg.t, *_packet(seg, seg.off + start, data, size, ident)))
            flow.sent = max(flow.sent, seg.off + start + size)
            start += size
    connections = len({tuple(sorted(key)) for key in builder.flows})
    ports = sorted({_endpoint(item.conn.server)[1] for item in items  # type: ignore[index]
                    if isinstance(item, Wire) and _endpoint(item.conn.server) is not None})
    return packets, connections, ports


def tshark_command(path: str, ports: List[int]) -> List[str]:
    """The tshark command that decodes every traced TCPROS connection of ``path``.

    Wireshark's tcpros_tcp heuristic only claims a connection when a packet looks like a
    message that starts with a std_msgs/Header (or a /clock message): it rejects connection
    headers (it wants their first field to be letters and digits only, and ``callerid=/x`` is
    not), so a std_msgs/String topic is never recognised. "Decode As" on the ports of the
    TCPROS servers decodes them all; ``-2`` (two passes) lets a connection the heuristic found
    later be decoded from its first packet."""
    command = ["tshark", "-r", path, "-2", "--enable-heuristic", "tcpros_tcp"]
    for port in ports:
        command += ["-d", f"tcp.port=={port},tcpros"]
    return command


def write(out: BinaryIO, packets: List[Tuple[float, bytes, int]]) -> None:
    """A libpcap file (microsecond timestamps, raw IP)."""
    out.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, SNAPLEN, LINKTYPE_RAW))
    for t, data, size in packets:
        sec = int(t)
        usec = min(999999, int(round((t - sec) * 1e6)))
        out.write(struct.pack("<IIII", sec, usec, len(data), size))
        out.write(data)
