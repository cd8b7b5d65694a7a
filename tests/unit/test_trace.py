"""The wire trace (minros.wire.trace) and its readers (minros.tools.trace): what is recorded,
how the two views of one exchange are joined, the numbered sequence, the pcap, bad input."""

from __future__ import annotations

import io
import json
import os
import socket
import struct
import subprocess
import sys
import threading
import xmlrpc.client
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from minros.cli import trace as trace_cli
from minros.msgs import get_message_class
from minros.tools.trace import merge, pcap, show
from minros.wire import tcpros, trace
from minros.wire.xmlrpc import ServerProxy, XmlRpcServer

String = get_message_class("std_msgs/String")
STRING_MD5 = "992ce8a1687cec8c8bd883ec73ca41d1"


@pytest.fixture
def traced(tmp_path, monkeypatch):
    """Trace this process into a fresh file; yields a function returning its events."""
    path = tmp_path / "trace.jsonl"
    monkeypatch.setenv(trace.ENV_FILE, str(path))
    assert trace.start(str(path))
    trace.set_node("/tester", "http://localhost:1/", "http://localhost:11311/")

    def events():
        return [json.loads(line) for line in path.read_text().splitlines()]

    events.path = path
    try:
        yield events
    finally:
        trace.stop()


def _frame(payload: bytes) -> bytes:
    return struct.pack("<I", len(payload)) + payload


def _topic_bytes(count: int = 3):
    """A subscriber's header, then a publisher's header and ``count`` String frames."""
    sub = tcpros.encode_header({"topic": "/chatter", "md5sum": STRING_MD5, "callerid": "/listener",
                                "type": "std_msgs/String", "message_definition": "string data\n",
                                "tcp_nodelay": "0"})
    pub = tcpros.encode_header({"topic": "/chatter", "md5sum": STRING_MD5, "callerid": "/talker",
                                "type": "std_msgs/String", "message_definition": "string data\n",
                                "latching": "0"})
    frames = []
    for i in range(count):
        buf = io.BytesIO()
        String(f"hello world {i}").serialize(buf)
        frames.append(_frame(buf.getvalue()))
    return sub, pub, frames


# --------------------------------------------------------------------------- plain values


def test_plain_abbreviates_what_could_be_large():
    assert trace.plain("x" * 300) == "x" * 256 + "…(+44 chars)"
    listed = trace.plain(list(range(40)))
    assert listed[:32] == list(range(32)) and listed[32] == "…(+8 items)"
    assert trace.plain(b"\x01\x02") == {"hex": "0102", "len": 2}
    assert trace.plain(bytes(100))["hex"].endswith("…(+68 bytes)")
    assert trace.plain(float("nan")) == "nan"
    assert trace.plain(xmlrpc.client.Binary(b"abc")) == {"base64": "YWJj", "len": 3}
    Header = get_message_class("std_msgs/Header")
    header = Header(seq=3, frame_id="map")
    header.stamp.secs, header.stamp.nsecs = 5, 6
    assert trace.plain(header) == {"seq": 3, "stamp": {"secs": 5, "nsecs": 6}, "frame_id": "map"}
    deep = current = []
    for _ in range(20):
        current.append([])
        current = current[0]
    assert "…" in json.dumps(trace.plain(deep), ensure_ascii=False)


def test_addresses_read_as_host_port():
    assert trace.address(("127.0.0.1", 80)) == "127.0.0.1:80"
    assert trace.address(("::1", 80, 0, 0)) == "[::1]:80"


# --------------------------------------------------------------------------- TCPROS


def test_a_topic_connection_is_traced_from_both_ends(traced, monkeypatch):
    monkeypatch.setattr(trace._writer, "messages", True)
    a, b = socket.socketpair()
    client, server = trace.watch(a, "connect"), trace.watch(b, "accept")
    sub, pub, frames = _topic_bytes()
    client.sendall(sub)
    server.recv_into(bytearray(len(sub)))
    server.sendall(pub)
    client.recv(len(pub))
    server.sendmsg([frames[0], frames[1]])
    server.send(frames[2])
    buf = bytearray(1024)
    got = 0
    while got < sum(map(len, frames)):
        got += client.recv_into(memoryview(buf)[got:])
    client.close()
    assert server.recv(10) == b""
    server.close()
    events = traced()
    kinds = [(e["ev"], e.get("conn"), e.get("dir")) for e in events if e["ev"] != "node"]
    assert kinds[:3] == [("process", None, None), ("tcp.open", 1, None), ("tcp.open", 2, None)]
    headers = [e for e in events if e["ev"] == "tcpros.header"]
    assert [(h["conn"], h["dir"], h["len"]) for h in headers] == [
        (1, "out", len(sub)), (2, "in", len(sub)), (2, "out", len(pub)), (1, "in", len(pub))]
    assert dict(headers[0]["fields"])["callerid"] == "/listener"
    assert all(h["topic"] == "/chatter" for h in headers)
    sent = [e for e in events if e["ev"] == "tcpros.frame" and e["dir"] == "out"]
    received = [e for e in events if e["ev"] == "tcpros.frame" and e["dir"] == "in"]
    offsets = [len(pub), len(pub) + len(frames[0]), len(pub) + len(frames[0]) + len(frames[1])]
    for got_frames in (sent, received):
        assert [f["n"] for f in got_frames] == [1, 2, 3]
        assert [f["off"] for f in got_frames] == offsets
        assert [f["len"] for f in got_frames] == [len(f) - 4 for f in frames]
        assert got_frames[0]["head"] == frames[0][4:].hex()
        assert [f["msg"] for f in got_frames] == [{"data": f"hello world {i}"} for i in range(3)]
    closes = {e["conn"]: e for e in events if e["ev"] == "tcp.close"}
    assert closes[1]["sent"] == len(sub) and closes[1]["frames_in"] == 3
    assert closes[2]["received"] == len(sub) and closes[2]["frames_out"] == 3
    assert [e["conn"] for e in events if e["ev"] == "tcp.eof"] == [2]


def test_service_responses_are_read_with_their_ok_byte(traced):
    a, b = socket.socketpair()
    client, server = trace.watch(a, "connect"), trace.watch(b, "accept")
    hello = tcpros.encode_header({"service": "/add_two_ints", "md5sum": "*",
                                  "callerid": "/client"})
    client.sendall(hello)
    assert len(server.recv(len(hello))) == len(hello)  # the server learns it is a service
    server.sendall(tcpros.encode_header({"service": "/add_two_ints", "callerid": "/server",
                                         "type": "rospy_tutorials/AddTwoInts", "md5sum": "x"}))
    request = _frame(struct.pack("<qq", 4, 5))
    client.sendall(request)
    assert server.recv(100) == request
    server.sendall(tcpros.encode_service_response(struct.pack("<q", 9)))
    server.sendall(tcpros.encode_service_error("no"))
    client.close()
    server.close()
    frames = [e for e in traced() if e["ev"] == "tcpros.frame"]
    assert [(f["conn"], f["dir"], f.get("ok"), f["len"]) for f in frames] == [
        (1, "out", None, 16), (2, "in", None, 16), (2, "out", 1, 8), (2, "out", 0, 2)]
    assert all(f["service"] == "/add_two_ints" for f in frames)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(min_value=1, max_value=60), min_size=1, max_size=40))
def test_frames_are_found_however_the_bytes_are_cut(tmp_path_factory, cuts):
    path = tmp_path_factory.mktemp("cuts") / "t.jsonl"
    trace.start(str(path))
    try:
        _sub, pub, frames = _topic_bytes(4)
        stream = pub + b"".join(frames) + _frame(b"")
        conn = trace._Connection("connect", trace._writer)
        tap = trace._Tap(conn, "in")
        pos = i = 0
        while pos < len(stream):
            step = cuts[i % len(cuts)]
            tap.feed(stream[pos:pos + step], 1.0)
            pos += step
            i += 1
    finally:
        trace.stop()
    events = [json.loads(line) for line in path.read_text().splitlines()]
    got = [(e["ev"], e.get("off"), e.get("len"), e.get("head")) for e in events[1:]]
    expected = [("tcpros.header", 0, len(pub), None)]
    off = len(pub)
    for frame in frames + [_frame(b"")]:
        expected.append(("tcpros.frame", off, len(frame) - 4, frame[4:68].hex()))
        off += len(frame)
    assert got == expected


def test_bytes_that_are_not_tcpros_are_traced_as_data(traced):
    a, b = socket.socketpair()
    server = trace.watch(b, "accept")
    a.sendall(b"GET / HTTP/1.1\r\n\r\n")
    server.recv(100)
    a.close()
    server.close()
    data = [e for e in traced() if e["ev"] == "tcp.data"]
    assert len(data) == 1 and bytes.fromhex(data[0]["head"]).startswith(b"GET / HTTP/1.1")


def test_frames_beyond_the_limit_are_counted_not_written(traced, monkeypatch):
    monkeypatch.setattr(trace._writer, "frame_limit", 2)
    a, b = socket.socketpair()
    client = trace.watch(a, "connect")
    _sub, pub, frames = _topic_bytes(5)
    b.sendall(pub + b"".join(frames))
    want = len(pub) + sum(map(len, frames))
    got = 0
    while got < want:
        got += len(client.recv(4096))
    client.close()
    b.close()
    events = traced()
    assert len([e for e in events if e["ev"] == "tcpros.frame"]) == 2
    close = [e for e in events if e["ev"] == "tcp.close"][0]
    assert close["frames_in"] == 5 and close["untraced_in"] == 3 and close["received"] == want


def test_untraced_sockets_are_left_alone():
    assert not trace.ON
    a, b = socket.socketpair()
    assert trace.watch(a, "connect") is a
    a.close()
    b.close()


# --------------------------------------------------------------------------- XML-RPC


class _Api:
    def add(self, caller_id, a, b):
        return [1, "sum", a + b]

    def boom(self, caller_id):
        raise ValueError("no such thing")


def test_xmlrpc_calls_are_traced_at_both_ends_and_merged(traced):
    server = XmlRpcServer(_Api(), "127.0.0.1", 0).start()
    try:
        proxy = ServerProxy(f"http://127.0.0.1:{server.port}/")
        assert proxy.add("/me", 2, 3) == [1, "sum", 5]
        with pytest.raises(xmlrpc.client.Fault):
            proxy.boom("/me")
        proxy.close()
    finally:
        server.shutdown()
    with pytest.raises(OSError):
        ServerProxy(f"http://127.0.0.1:{server.port}/", timeout=1).add("/me", 1, 1)
    events = traced()
    calls = [e for e in events if e["ev"] == "xmlrpc.call"]
    served = [e for e in events if e["ev"] == "xmlrpc.serve"]
    assert [(c["method"], c["n"]) for c in calls[:2]] == [("add", 1), ("boom", 2)]
    assert [(s["method"], s["n"]) for s in served] == [("add", 1), ("boom", 2)]
    assert calls[0]["reply"] == served[0]["reply"] == [1, "sum", 5]
    assert calls[0]["local"] == served[0]["remote"] and calls[0]["remote"] == served[0]["local"]
    assert calls[0]["request"].startswith("POST / HTTP/1.1\r\n")
    assert "<methodName>add</methodName>" in calls[0]["request"]
    assert calls[0]["request_len"] == len(calls[0]["request"].encode())
    assert calls[0]["response"] == served[0]["response"]
    assert "no such thing" in calls[1]["fault"] and "no such thing" in served[1]["fault"]
    assert "ConnectionRefusedError" in calls[2]["error"] and "local" not in calls[2]
    # one Call per exchange, whichever end was traced
    trace_file = merge.load(str(traced.path))
    (run,) = merge.split_runs([trace_file])
    items, _names = merge.merge(run)
    assert [(i.method, i.views) for i in items] == [
        ("add", ["call", "serve"]), ("boom", ["call", "serve"]), ("add", ["call"])]


# --------------------------------------------------------------------------- the sequence


def _ev(t, pid, node, ev, **fields):
    return {"t": t, "pid": pid, "node": node, "ev": ev, **fields}


def _header_len(fields) -> int:
    return len(tcpros.encode_header(dict(fields)))


def _talker_first_trace(t0: float = 1000.0, master_port: int = 11311):
    """A hand-written run: the talker registers first, so the master's answer to
    registerSubscriber carries the publisher and no publisherUpdate is sent."""
    master = f"http://localhost:{master_port}/"
    talker, listener = "http://localhost:40001/", "http://localhost:40002/"
    pair = [["callerid", "/listener"], ["md5sum", STRING_MD5], ["topic", "/chatter"],
            ["type", "std_msgs/String"], ["message_definition", "string data\n"]]
    back = [["callerid", "/talker"], ["md5sum", STRING_MD5], ["topic", "/chatter"],
            ["type", "std_msgs/String"], ["message_definition", "string data\n"], ["latching", "0"]]
    return [
        _ev(t0, 1, "talker.py", "process", argv=["talker.py"], master=master),
        _ev(t0 + .1, 1, "/talker", "node", name="/talker", uri=talker, master=master),
        _ev(t0 + .2, 1, "/talker", "xmlrpc.call", uri=master, local="127.0.0.1:50001",
            remote=f"127.0.0.1:{master_port}", n=1, method="registerPublisher",
            args=["/talker", "/chatter", "std_msgs/String", talker], reply=[1, "ok", []],
            request="POST / HTTP/1.1\r\n\r\n<x/>", request_len=23, t_reply=t0 + .21),
        _ev(t0 + .3, 2, "listener.py", "process", argv=["listener.py"], master=master),
        _ev(t0 + .4, 2, "/listener", "node", name="/listener", uri=listener, master=master),
        _ev(t0 + .5, 2, "/listener", "xmlrpc.call", uri=master, local="127.0.0.1:50002",
            remote=f"127.0.0.1:{master_port}", n=1, method="registerSubscriber",
            args=["/listener", "/chatter", "std_msgs/String", listener],
            reply=[1, "Subscribed to [/chatter]", [talker]], t_reply=t0 + .51),
        _ev(t0 + .6, 2, "/listener", "xmlrpc.call", uri=talker, local="127.0.0.1:50003",
            remote="127.0.0.1:40001", n=1, method="requestTopic",
            args=["/listener", "/chatter", [["TCPROS"]]],
            reply=[1, "ready", ["TCPROS", "localhost", 40010]], t_reply=t0 + .61),
        _ev(t0 + .7, 2, "/listener", "tcp.open", conn=1, side="connect", local="127.0.0.1:50004",
            remote="127.0.0.1:40010"),
        _ev(t0 + .71, 2, "/listener", "tcpros.header", conn=1, topic="/chatter", dir="out",
            off=0, len=_header_len(pair), fields=pair),
        _ev(t0 + .72, 1, "/talker", "tcp.open", conn=1, side="accept", local="127.0.0.1:40010",
            remote="127.0.0.1:50004"),
        _ev(t0 + .73, 1, "/talker", "tcpros.header", conn=1, topic="/chatter", dir="in", off=0,
            len=_header_len(pair), fields=pair),
        _ev(t0 + .74, 1, "/talker", "tcpros.header", conn=1, topic="/chatter", dir="out", off=0,
            len=_header_len(back), fields=back),
        _ev(t0 + .75, 2, "/listener", "tcpros.header", conn=1, topic="/chatter", dir="in",
            off=0, len=_header_len(back), fields=back),
        _ev(t0 + .8, 1, "/talker", "tcpros.frame", conn=1, topic="/chatter", dir="out", n=1,
            off=_header_len(back), len=17, head=(b"\x0d\0\0\0hello world 0").hex(),
            msg={"data": "hello world 0"}),
        _ev(t0 + .81, 2, "/listener", "tcpros.frame", conn=1, topic="/chatter", dir="in", n=1,
            off=_header_len(back), len=17, head=(b"\x0d\0\0\0hello world 0").hex()),
        _ev(t0 + .9, 2, "/listener", "tcp.close", conn=1, topic="/chatter",
            local="127.0.0.1:50004", remote="127.0.0.1:40010", sent=_header_len(pair), received=_header_len(back) + 21,
            frames_in=1, frames_out=0),
    ]


def _write(path: Path, events) -> str:
    path.write_text("".join(json.dumps(e) + "\n" for e in events))
    return str(path)


def _steps(lines):
    import re

    return [m.group(1) for m in (re.match(r"\s*\[(\d)\]\s+\+\d", line) for line in lines) if m]


def test_show_numbers_the_course_sequence(tmp_path):
    trace_file = merge.load(_write(tmp_path / "t.jsonl", _talker_first_trace()))
    lines = list(show.render(merge.split_runs([trace_file]), show.Filter()))
    text = "\n".join(lines)
    # talker first: [0], [1] whose answer is [2], [3] with its answer [4], [5] x3, [6]
    assert _steps(lines) == ["0", "1", "2", "3", "4", "5", "5", "5", "6"], text
    assert "/listener -> /talker" in text and "/talker -> /listener" in text
    assert "connection header: length prefix" in text and "md5sum=" + STRING_MD5 in text
    assert 'message 1: length prefix 11000000 = 17 bytes' in text
    assert '= {"data": "hello world 0"}' in text  # the decoded view, from the sender's side
    assert "/listener x /talker" in text and "closed the connection" in text


def test_a_file_cut_in_the_middle_is_read_up_to_the_cut(tmp_path, capsys):
    events = _talker_first_trace()
    raw = "".join(json.dumps(e) + "\n" for e in events)
    cut = raw.index('"ev": "tcpros.frame"') + 10
    path = tmp_path / "cut.jsonl"
    path.write_text(raw[:cut])
    loaded = merge.load(str(path))
    assert len(loaded.events) == 13
    assert loaded.stop.startswith(f"{path} stops at line 14 (byte {raw[:cut].rindex(chr(10)) + 1})")
    assert "cut off" in loaded.stop
    assert trace_cli.main(["show", str(path)]) == 0
    out, err = capsys.readouterr()
    assert "connection header" in out and "message 1" not in out
    assert err.strip() == f"minros trace show: {loaded.stop}"


def test_a_file_that_is_not_a_trace_is_refused_in_one_line(tmp_path, capsys):
    path = tmp_path / "notes.txt"
    path.write_text("hello\n")
    assert trace_cli.main(["show", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is not a minros trace: line 1" in err
    empty = tmp_path / "empty.jsonl"
    empty.write_text("")
    assert trace_cli.main(["show", str(empty)]) == 1
    assert "is empty" in capsys.readouterr().err
    assert trace_cli.main(["show", str(tmp_path / "missing.jsonl")]) == 1
    assert "cannot read" in capsys.readouterr().err


def test_unrelated_runs_are_shown_apart(tmp_path, capsys):
    first = _write(tmp_path / "a.jsonl", _talker_first_trace(1000.0))
    later = _write(tmp_path / "b.jsonl", _talker_first_trace(5000.0))
    elsewhere = _write(tmp_path / "c.jsonl", _talker_first_trace(1000.0, master_port=11400))
    runs = merge.split_runs([merge.load(p) for p in (first, later, elsewhere)])
    assert len(runs) == 3 and all(len(run.processes) == 2 for run in runs)
    # one file holding two runs appended one after the other splits the same way
    both = tmp_path / "both.jsonl"
    both.write_text(Path(first).read_text() + Path(later).read_text())
    assert trace_cli.main(["show", str(both)]) == 0
    out = capsys.readouterr().out
    assert "these traces hold 2 unrelated runs" in out
    assert "run 1 of 2:" in out and "run 2 of 2:" in out
    assert _steps(out.splitlines()) == ["0", "1", "2", "3", "4", "5", "5", "5", "6"] * 2
    # processes of one session, traced into separate files, are one run
    events = _talker_first_trace()
    talker = [e for e in events if e["pid"] == 1]
    listener = [e for e in events if e["pid"] == 2]
    parts = [merge.load(_write(tmp_path / "t.jsonl", talker)),
             merge.load(_write(tmp_path / "l.jsonl", listener))]
    assert len(merge.split_runs(parts)) == 1


def test_filters_and_frame_limits(tmp_path, capsys):
    path = _write(tmp_path / "t.jsonl", _talker_first_trace())
    assert trace_cli.main(["show", "--topic", "/other", path]) == 0
    assert "topic /chatter" not in capsys.readouterr().out
    assert trace_cli.main(["show", "--frames", "0", path]) == 0
    out = capsys.readouterr().out
    assert "message 1" not in out and "… 1 more frames, 21 bytes" in out


def test_follow_prints_events_as_they_arrive(tmp_path):
    events = _talker_first_trace()
    path = tmp_path / "live.jsonl"
    path.write_text("")
    follower = merge.Follower([str(path)])
    view = show.LiveView(show.Filter())
    with open(path, "a") as out:
        for ev in events[:6]:
            out.write(json.dumps(ev) + "\n")
        out.write(json.dumps(events[6])[:20])  # a line being written
    first = view.feed(follower.poll())
    assert any("registerSubscriber" in line for line in first)
    assert not any("requestTopic" in line for line in first)
    with open(path, "a") as out:
        out.write(json.dumps(events[6])[20:] + "\n")
        for ev in events[7:]:
            out.write(json.dumps(ev) + "\n")
    later = view.feed(follower.poll())
    assert any(line.startswith("topic /chatter: [3]") and "requestTopic" in line for line in later)
    assert sum("connection header" in line for line in later) == 2  # not 4: both ends merged
    assert sum("message 1" in line for line in later) == 1


# --------------------------------------------------------------------------- pcap


def _read_pcap(data: bytes):
    magic, major, minor, _zone, _sig, snaplen, linktype = struct.unpack_from("<IHHiIII", data)
    assert (magic, major, minor, linktype) == (0xA1B2C3D4, 2, 4, pcap.LINKTYPE_RAW)
    pos, packets = 24, []
    while pos < len(data):
        sec, usec, incl, orig = struct.unpack_from("<IIII", data, pos)
        packets.append((sec + usec / 1e6, data[pos + 16:pos + 16 + incl], orig))
        pos += 16 + incl
    return packets


def test_the_pcap_holds_consistent_tcp_streams(tmp_path):
    trace_file = merge.load(_write(tmp_path / "t.jsonl", _talker_first_trace()))
    items = merge.merge(merge.split_runs([trace_file])[0])[0]
    packets, connections, ports = pcap.build(items)
    assert connections == 4 and ports == [40010]
    out = io.BytesIO()
    pcap.write(out, packets)
    read = _read_pcap(out.getvalue())
    assert len(read) == len(packets)
    streams = {}
    for _t, ip, orig in read:
        assert ip[0] >> 4 == 4 and pcap._checksum(ip[:20]) == 0  # a valid IPv4 header
        total = struct.unpack_from("!H", ip, 2)[0]
        assert total == orig
        src, dst = ip[12:16], ip[16:20]
        sport, dport, seq, ack, _off, flags = struct.unpack_from("!HHIIBB", ip, 20)
        payload = ip[40:]
        key = (src, sport, dst, dport)
        if flags & 0x02:
            streams[key] = seq + 1
            continue
        if payload or flags & 0x01:
            assert seq == streams[key], "segments follow each other without gaps here"
            streams[key] += (orig - 40) + (1 if flags & 0x01 else 0)
        if len(payload) == orig - 40:  # fully captured: the TCP checksum must hold
            pseudo = src + dst + struct.pack("!BBH", 0, 6, orig - 20)
            assert pcap._checksum(pseudo + ip[20:]) == 0
    tcpros_stream = [p for _t, p, _o in read
                     if struct.unpack_from("!H", p, 22)[0] == 40010 and len(p) > 40]
    header = tcpros_stream[0][40:]
    assert header == pcap._header_bytes(_talker_first_trace()[8]["fields"])


def test_pcap_subcommand_writes_a_file_and_says_how_to_open_it(tmp_path, capsys):
    path = _write(tmp_path / "t.jsonl", _talker_first_trace())
    out_path = tmp_path / "t.pcap"
    assert trace_cli.main(["pcap", path, "-o", str(out_path)]) == 0
    out = capsys.readouterr().out
    assert f"to {out_path}" in out and "-d tcp.port==40010,tcpros" in out
    assert len(_read_pcap(out_path.read_bytes())) > 10


# --------------------------------------------------------------------------- bad files


@pytest.mark.slow
def test_an_unwritable_trace_file_costs_one_line_and_nothing_else(tmp_path):
    target = tmp_path / "no" / "such" / "dir" / "t.jsonl"
    env = dict(os.environ, MINROS_TRACE=str(target))
    code = ("from minros.wire import trace, xmlrpc\n"
            "import os\n"
            "print(trace.ON, os.environ.get('MINROS_TRACE'))\n")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          timeout=30)
    assert done.returncode == 0
    assert done.stdout.strip() == "False None"  # untraced, and its children will not retry
    assert done.stderr.count("\n") == 1 and f"cannot write the trace to {target}" in done.stderr
    assert "running without a trace" in done.stderr


@pytest.mark.slow
def test_minros_trace_runs_the_command_untraced_when_it_cannot_write(tmp_path):
    target = tmp_path / "missing" / "t.jsonl"
    done = subprocess.run([sys.executable, "-m", "minros", "trace", "-o", str(target), "--",
                           sys.executable, "-c",
                           "import os; print('ran', os.environ.get('MINROS_TRACE'))"],
                          capture_output=True, text=True, timeout=30)
    assert done.returncode == 0
    assert done.stdout.strip() == "ran None"
    assert done.stderr.count("\n") == 1 and "cannot write the trace" in done.stderr


@pytest.mark.slow
def test_minros_trace_passes_the_exit_status_and_the_settings(tmp_path):
    target = tmp_path / "t.jsonl"
    code = ("import os, sys; e = os.environ; print(e['MINROS_TRACE'], e['MINROS_TRACE_MESSAGES'],"
            " e['MINROS_TRACE_FRAMES'], e['MINROS_TRACE_BYTES']); sys.exit(3)")
    done = subprocess.run([sys.executable, "-m", "minros", "trace", "-o", str(target),
                           "--messages", "--frames", "all", "--bytes", "16", "--",
                           sys.executable, "-c", code], capture_output=True, text=True, timeout=30)
    assert done.returncode == 3
    assert done.stdout.split() == [str(target), "1", "all", "16"]
    assert f"tracing into {target}; read it with: minros trace show" in done.stderr
    missing = subprocess.run([sys.executable, "-m", "minros", "trace", "-o", str(target), "--",
                              "no-such-program-here"], capture_output=True, text=True, timeout=30)
    assert missing.returncode == 127 and "cannot run no-such-program-here" in missing.stderr


def test_a_failing_write_stops_tracing_with_one_line(tmp_path, capsys):
    path = tmp_path / "t.jsonl"
    assert trace.start(str(path))
    try:
        os.close(trace._writer.fd)  # as if the disk went away
        trace.event("tcp.open", conn=1)
        trace.event("tcp.open", conn=2)
        assert not trace.ON
    finally:
        trace._writer.fd = -1
        trace.stop()
    assert capsys.readouterr().err.count("cannot write the trace") == 1


def test_tracing_threads_write_whole_lines(traced):
    def worker(k):
        for i in range(200):
            trace.event("tcp.data", conn=k, n=i, head="ab" * 50)

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    events = traced()  # every line parses
    assert len([e for e in events if e["ev"] == "tcp.data"]) == 800
