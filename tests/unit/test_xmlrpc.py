"""minros.wire.xmlrpc: dispatch, faults, keep-alive, limits and hostile clients (loopback sockets)."""

from __future__ import annotations

import select
import socket
import threading
import time
import xmlrpc.client

import pytest

from minros import rosenv
from minros.wire import xmlrpc as mx
from minros.wire.admission import Limits


class Handler:
    def __init__(self) -> None:
        self.release = threading.Event()

    def add(self, a, b):
        return a + b

    def echo(self, value):
        return value

    def none(self):
        return None

    def slow(self, seconds):
        self.release.wait(seconds)
        return 1

    def _secret(self):
        return "hidden"


@pytest.fixture
def server():
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", idle_timeout=5.0).start()
    yield srv
    srv.shutdown()


def uri(srv) -> str:
    return f"http://127.0.0.1:{srv.port}/"


def raw_post(port: int, body: bytes, extra: bytes = b"", version: bytes = b"HTTP/1.1") -> bytes:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
        s.sendall(b"POST / " + version + b"\r\nContent-Length: " + str(len(body)).encode()
                  + b"\r\n" + extra + b"\r\n" + body)
        return _read_all(s)


def _read_all(s: socket.socket) -> bytes:
    chunks = []
    while True:
        try:
            data = s.recv(65536)
        except socket.timeout:
            break
        if not data:
            break
        chunks.append(data)
        if b"</methodResponse>" in b"".join(chunks):
            break
    return b"".join(chunks)


def test_calls_faults_and_introspection(server):
    proxy = mx.ServerProxy(uri(server))
    assert proxy.add(2, 3) == 5
    assert proxy.echo({"a": [1, "x", 2.5, True]}) == {"a": [1, "x", 2.5, True]}
    assert proxy.system.listMethods() == ["add", "echo", "none", "slow", "system.listMethods",
                                          "system.multicall"]
    with pytest.raises(xmlrpc.client.Fault) as info:
        proxy.nope()
    assert info.value.faultCode == 1
    assert info.value.faultString == "<class 'Exception'>:method \"nope\" is not supported"
    with pytest.raises(xmlrpc.client.Fault, match="not supported"):
        proxy._secret()
    with pytest.raises(xmlrpc.client.Fault, match="TypeError"):
        proxy.add(1)
    # allow_none is off: a None result is a marshalling fault, not a crash
    with pytest.raises(xmlrpc.client.Fault, match="cannot marshal None"):
        proxy.none()
    assert proxy.add(1, 1) == 2  # the server is still fine


def test_multicall_matches_stdlib_shape(server):
    proxy = mx.ServerProxy(uri(server))
    multi = xmlrpc.client.MultiCall(proxy)
    multi.add(1, 2)
    multi.nope()
    multi.echo("x")
    results = multi().results
    assert results[0] == [3]
    assert results[1]["faultCode"] == 1 and "not supported" in results[1]["faultString"]
    assert results[2] == ["x"]


def test_stdlib_client_interoperates(server):
    proxy = xmlrpc.client.ServerProxy(uri(server))
    assert proxy.add("a", "b") == "ab"
    assert proxy.echo(xmlrpc.client.Binary(b"\x00\xff")).data == b"\x00\xff"


def test_malformed_xml_is_a_fault(server):
    reply = raw_post(server.port, b"<methodCall><methodName>add</methodName><params>")
    assert b"200 OK" in reply.split(b"\r\n")[0]
    assert b"faultCode" in reply and b"ExpatError" in reply


def test_entity_expansion_bomb_refused_quickly(server):
    bomb = (b'<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol">'
            + b"".join(b'<!ENTITY lol%d "%s">' % (i, (b"&lol%d;" % (i - 1) if i else b"&lol;") * 10)
                       for i in range(1, 10))
            + b']><methodCall><methodName>echo</methodName><params><param><value>'
            b"&lol9;</value></param></params></methodCall>")
    start = time.monotonic()
    reply = raw_post(server.port, bomb)
    assert time.monotonic() - start < 2.0
    assert b"faultCode" in reply and b"not allowed" in reply
    assert len(reply) < 10000


def test_oversize_body_refused_before_reading():
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", max_body=1000).start()
    try:
        with socket.create_connection(("127.0.0.1", srv.port), timeout=5) as s:
            # Announce 1 GiB and send nothing: the answer must come from the header alone.
            s.sendall(b"POST / HTTP/1.1\r\nContent-Length: 1073741824\r\n\r\n")
            reply = _read_all(s)
        assert reply.startswith(b"HTTP/1.1 413")
        assert mx.ServerProxy(f"http://127.0.0.1:{srv.port}/").add(1, 2) == 3
    finally:
        srv.shutdown()


@pytest.mark.parametrize("request_bytes, status", [
    (b"GET / HTTP/1.1\r\n\r\n", b"501"),
    (b"POST /other HTTP/1.1\r\nContent-Length: 0\r\n\r\n", b"404"),
    (b"POST / HTTP/1.1\r\n\r\n", b"411"),
    (b"POST / HTTP/1.1\r\nContent-Length: x\r\n\r\n", b"400"),
    (b"garbage\r\n\r\n", b"400"),
    (b"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n", b"411"),
])
def test_bad_http_gets_one_status_and_close(server, request_bytes, status):
    with socket.create_connection(("127.0.0.1", server.port), timeout=5) as s:
        s.sendall(request_bytes)
        reply = _read_all(s)
    assert reply.split(b" ")[1] == status


def test_keep_alive_and_http10_close(server):
    body = xmlrpc.client.dumps((1, 2), "add").encode()
    with socket.create_connection(("127.0.0.1", server.port), timeout=5) as s:
        for _ in range(3):  # three requests on one connection
            s.sendall(b"POST / HTTP/1.1\r\nContent-Length: %d\r\n\r\n" % len(body) + body)
            assert b"<int>3</int>" in _read_all(s)
    reply = raw_post(server.port, body, version=b"HTTP/1.0")
    assert b"Connection: close" in reply


def test_silent_clients_are_dropped_after_idle_timeout():
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", idle_timeout=0.3).start()
    try:
        s = socket.create_connection(("127.0.0.1", srv.port), timeout=5)
        start = time.monotonic()
        assert s.recv(10) == b""  # the server closed on us
        assert 0.2 < time.monotonic() - start < 3.0
        s.close()
        assert srv.connection_count() == 0 or mx.ServerProxy(
            f"http://127.0.0.1:{srv.port}/").add(1, 1) == 2
    finally:
        srv.shutdown()


def test_client_retries_once_when_server_closed_idle_connection():
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", idle_timeout=0.2).start()
    try:
        proxy = mx.ServerProxy(f"http://127.0.0.1:{srv.port}/")
        assert proxy.add(1, 1) == 2
        # the server closes the idle connection: the client's socket reads the end of it
        assert select.select([proxy._sock], [], [], 3)[0], "the idle connection was kept"
        assert proxy.add(2, 2) == 4  # on a new connection, without an error
    finally:
        srv.shutdown()


def test_client_timeout(server):
    proxy = mx.ServerProxy(uri(server), timeout=0.2)
    start = time.monotonic()
    with pytest.raises(OSError):
        proxy.slow(5)
    assert time.monotonic() - start < 2
    server.dispatcher.handler.release.set()


def test_many_silent_clients_do_not_block_others(server):
    silent = [socket.create_connection(("127.0.0.1", server.port), timeout=5) for _ in range(300)]
    try:
        proxy = mx.ServerProxy(uri(server))
        start = time.monotonic()
        for i in range(20):
            assert proxy.add(i, 1) == i + 1
        # a server that a silent client blocked would answer after its idle timeout (5 s) at
        # the earliest; 20 calls take milliseconds, seconds on a starved machine
        assert time.monotonic() - start < 4.0
    finally:
        for s in silent:
            s.close()


def test_connection_bound_reclaims_idle_connections():
    limits = Limits(max_connections=2, peer_share=1.0, idle_timeout=30)
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", limits=limits).start()
    try:
        # two kept-alive clients, idle after one call each (answered: both are admitted)
        idle = [mx.ServerProxy(f"http://127.0.0.1:{srv.port}/", timeout=5) for _ in range(2)]
        for i, client in enumerate(idle):
            assert client.add(i, 1) == i + 1
        proxy = mx.ServerProxy(f"http://127.0.0.1:{srv.port}/", timeout=5)
        start = time.monotonic()
        assert proxy.add(1, 2) == 3  # served at once: an idle connection was closed for it
        assert time.monotonic() - start < 2.0
        # one idle connection was closed: the longest idle (which one that is cannot be told
        # here: the server marks a connection idle after its reply, after the client has it;
        # the order is test_admission's test_full_server_evicts_what_produced_nothing_for_longest)
        readable, _, _ = select.select([client._sock for client in idle], [], [], 5)
        assert len(readable) == 1 and readable[0].recv(10) == b""
        assert srv.connection_count() <= 2
        # a kept-alive client whose connection gets reclaimed simply reconnects
        other = mx.ServerProxy(f"http://127.0.0.1:{srv.port}/", timeout=5)
        for i in range(5):
            assert other.add(i, 1) == i + 1
            assert proxy.add(i, 2) == i + 2
        for client in idle:
            client.close()
    finally:
        srv.shutdown()


def test_concurrent_clients(server):
    errors = []

    def worker(n):
        try:
            p = mx.ServerProxy(uri(server))
            for i in range(20):
                assert p.add(n, i) == n + i
        except Exception as exc:  # noqa: BLE001
            errors.append(exc)

    threads = [threading.Thread(target=worker, args=(n,)) for n in range(50)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(20)
    assert not errors


def test_expect_100_continue(server):
    body = xmlrpc.client.dumps((1, 2), "add").encode()
    with socket.create_connection(("127.0.0.1", server.port), timeout=5) as s:
        s.sendall(b"POST / HTTP/1.1\r\nExpect: 100-continue\r\nContent-Length: %d\r\n\r\n"
                  % len(body))
        assert s.recv(100) == b"HTTP/1.1 100 Continue\r\n\r\n"
        s.sendall(body)
        assert b"<int>3</int>" in _read_all(s)


def test_client_reports_bad_content_length_as_protocol_error():
    listener = socket.create_server(("127.0.0.1", 0))
    port = listener.getsockname()[1]

    def answer() -> None:
        conn, _ = listener.accept()
        with conn:
            conn.recv(65536)
            conn.sendall(b"HTTP/1.1 200 OK\r\nContent-Length: lots\r\n\r\n<methodResponse/>")

    thread = threading.Thread(target=answer, daemon=True)
    thread.start()
    try:
        with pytest.raises(xmlrpc.client.ProtocolError, match="bad Content-Length"):
            mx.ServerProxy(f"http://127.0.0.1:{port}/", timeout=5).add(1, 2)
    finally:
        thread.join(5)
        listener.close()


# --------------------------------------------------------------------------- the request reader


def test_request_reader_parses_heads_bodies_and_pipelined_requests():
    body = xmlrpc.client.dumps((1, 2), "add").encode()
    one = b"POST /RPC2 HTTP/1.1\r\nContent-Length: %d\r\n\r\n%s" % (len(body), body)
    reader = mx.RequestReader()
    reader.received(b"\r\n\r\n")  # stray blank lines between requests do not start one
    assert not reader.started() and reader.head() is None
    stream = one + b"POST / HTTP/1.0\nContent-Length: 3\n\nabc"  # bare LF and HTTP/1.0
    for i in range(len(stream)):  # byte by byte: the same requests come out
        reader.received(stream[i:i + 1])
        if reader.body() is not None:
            break
    head = reader.head()
    assert head.length == len(body) and head.keep_alive and reader.body() == body
    assert reader.next_request() == 0
    reader.received(stream[len(one):])
    head = reader.head()
    assert head.version == "HTTP/1.0" and not head.keep_alive and reader.body() == b"abc"
    reader.next_request()
    reader.received(one + one[:10])  # one whole request and the start of the next
    assert reader.body() == body and reader.next_request() == 10


@pytest.mark.parametrize("data, status", [
    (b"GET / HTTP/1.1\r\n\r\n", 501),
    (b"POST /x HTTP/1.1\r\nContent-Length: 0\r\n\r\n", 404),
    (b"POST / HTTP/2.0\r\n\r\n", 505),
    (b"POST / HTTP/1.1\r\n\r\n", 411),
    (b"POST / HTTP/1.1\r\nContent-Length: -1\r\n\r\n", 400),
    (b"POST / HTTP/1.1\r\nContent-Length: 2000\r\n\r\n", 413),
    (b"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n", 411),
    (b"POST / HTTP/1.1\r\nno colon\r\n\r\n", 400),
    (b"POST " + b"x" * 9000, 414),
    (b"POST / HTTP/1.1\r\n" + b"X: y\r\n" * 101 + b"\r\n", 431),
    (b"POST / HTTP/1.1\r\n" + b"X: " + b"y" * 9000 + b"\r\n\r\n", 431),
    (b"POST / HTTP/1.1\r\n" + (b"X: " + b"y" * 8000 + b"\r\n") * 110, 431),
])
def test_request_reader_refuses_bad_heads(data, status):
    reader = mx.RequestReader(max_body=1000)
    reader.received(data)
    with pytest.raises(mx._HttpError) as err:
        reader.head()
    assert err.value.status == status


def test_request_reader_keeps_only_what_arrived():
    reader = mx.RequestReader()
    reader.received(b"POST / HTTP/1.1\r\nContent-Length: 67108864\r\n\r\nab")
    assert reader.head().length == 64 << 20
    assert reader.body() is None and len(reader._body) == 2  # nothing allocated for the rest


# --------------------------------------------------------------------------- hostile clients


def _held_open(port: int, data: bytes, count: int) -> list:
    conns = []
    for _ in range(count):
        s = socket.create_connection(("127.0.0.1", port), timeout=5)
        s.sendall(data)
        conns.append(s)
    return conns


def _answer_times(port: int, calls: int) -> list:
    times = []
    for i in range(calls):
        start = time.perf_counter()
        assert mx.ServerProxy(f"http://127.0.0.1:{port}/", timeout=2.0).add(i, 1) == i + 1
        times.append(time.perf_counter() - start)
    return times


def test_announced_bodies_hold_no_memory_and_block_nobody():
    """Defect 1 of issue 18: four requests announcing 64 MiB and sending nothing stalled every
    other call, because the announced length was booked against the shared budget."""
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1").start()
    hostile = _held_open(srv.port, b"POST / HTTP/1.1\r\nContent-Length: 67108864\r\n\r\nx", 4)
    try:
        assert len(_answer_times(srv.port, 5)) == 5
        assert srv.admission.held() < 4096  # only the bytes that arrived are charged
    finally:
        for s in hostile:
            s.close()
        srv.shutdown()


def test_a_trickled_head_cannot_extend_its_deadline():
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", limits=Limits(head_timeout=0.5)).start()
    try:
        s = socket.create_connection(("127.0.0.1", srv.port), timeout=5)
        start = time.monotonic()
        s.settimeout(0.1)
        reply = b""
        for byte in b"POST / HTTP/1.1\r\nContent-Length: 5\r\nX-Slow: " + b"y" * 100:
            try:
                s.send(bytes([byte]))
                reply = s.recv(4096)
                break
            except socket.timeout:
                continue
            except OSError:
                break
        assert reply.startswith(b"HTTP/1.1 408 Request Timeout")
        assert b"request head not received within the deadline" in reply
        assert 0.4 < time.monotonic() - start < 3.0
        s.close()
    finally:
        srv.shutdown()


def test_a_trickled_body_cannot_extend_its_deadline():
    limits = Limits(head_timeout=0.3, min_rate=1000.0)  # 300 bytes: 0.3 + 0.3 s
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", limits=limits).start()
    try:
        s = socket.create_connection(("127.0.0.1", srv.port), timeout=5)
        start = time.monotonic()
        s.sendall(b"POST / HTTP/1.1\r\nContent-Length: 300\r\n\r\n")
        s.settimeout(0.05)
        reply = b""
        while not reply and time.monotonic() - start < 5:
            try:
                s.send(b"<")
                reply = s.recv(4096)
            except socket.timeout:
                continue
        assert b"408 Request Timeout" in reply and b"request body" in reply
        assert 0.5 < time.monotonic() - start < 3.0
        s.close()
    finally:
        srv.shutdown()


def test_a_full_server_of_trickling_clients_still_answers():
    """Defect 2 of issue 18 in small: at the cap the server closed only connections waiting for
    their first request line, so clients trickling their headers held it full."""
    limits = Limits(max_connections=20, peer_share=1.0)
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", limits=limits).start()
    tricklers = _held_open(srv.port, b"POST / HTTP/1.1\r\nX-Slow: ", 25)
    try:
        for s in tricklers:
            s.send(b"y")
        assert len(_answer_times(srv.port, 5)) == 5
        assert srv.connection_count() <= 20 and srv.admission.evictions >= 5
    finally:
        for s in tricklers:
            s.close()
        srv.shutdown()


def test_slow_bodies_filling_the_budget_are_closed_for_newer_requests():
    limits = Limits(budget=1500, peer_share=1.0)
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", max_body=1500, limits=limits).start()
    try:
        slow = _held_open(srv.port, b"POST / HTTP/1.1\r\nContent-Length: 1500\r\n\r\n"
                          + b"<" * 1400, 1)[0]
        wait = time.monotonic() + 3
        while srv.admission.held() < 1400 and time.monotonic() < wait:
            time.sleep(0.01)
        assert srv.admission.held() >= 1400
        assert _answer_times(srv.port, 3)  # each needs ~300 bytes: the slow one makes room
        assert slow.recv(100) == b""  # closed
        assert srv.admission.held() == 0
        slow.close()
    finally:
        srv.shutdown()


def test_peers_outside_the_allow_list_are_refused_with_one_reported_line():
    refused = []
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", allowed=rosenv.parse_allowed_hosts("10.9.9.0/24"),
                          on_refused=lambda peer, reason: refused.append(reason),
                          what="the master")
    for _ in range(3):
        ours, theirs = socket.socketpair()
        with ours, theirs:
            srv._admit(ours, ("192.168.5.5", 4000))  # as if accepted from that address
            reply = theirs.recv(4096)
        assert reply.startswith(b"HTTP/1.1 403 Forbidden")
        assert b"connection from 192.168.5.5 refused: not in ROS_ALLOWED_HOSTS of the master" in reply
    assert refused == ["connection from 192.168.5.5 refused: not in ROS_ALLOWED_HOSTS of the master"]
    srv.start()  # loopback peers are always served
    try:
        assert mx.ServerProxy(uri(srv)).add(1, 2) == 3
    finally:
        srv.shutdown()


# --------------------------------------------------------------------------- failures the client explains

def test_a_request_over_the_servers_limit_names_the_limit():
    """The server answers 413 and closes while the request is still being sent: the client
    reads that answer instead of reporting ConnectionResetError."""
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", max_body=1 << 20).start()
    try:
        with pytest.raises(mx.CallRefused) as info:
            mx.ServerProxy(uri(srv), timeout=10).echo("x" * (16 << 20))
    finally:
        srv.shutdown()
    assert info.value.errcode == 413 and isinstance(info.value, xmlrpc.client.ProtocolError)
    text = str(info.value)
    assert text.startswith(f"{uri(srv)} refused a request of 16777")
    assert "larger than its limit of 1048576 bytes (1 MiB) per XML-RPC call" in text


def test_an_allow_list_refusal_names_ros_allowed_hosts(monkeypatch):
    monkeypatch.setattr(rosenv, "host_allowed", lambda *args: False)  # loopback as a stranger
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", allowed=rosenv.parse_allowed_hosts("10.9.9.0/24"),
                          on_refused=lambda peer, reason: None, what="the master").start()
    try:
        for size in (10, 8 << 20):  # the large one is still being sent when the refusal comes
            with pytest.raises(mx.CallRefused) as info:
                mx.ServerProxy(uri(srv), timeout=10).echo("x" * size)
            assert info.value.errcode == 403
            assert str(info.value) == (
                f"{uri(srv)} refused this host: connection from 127.0.0.1 refused: not in "
                "ROS_ALLOWED_HOSTS of the master (add this host's address to ROS_ALLOWED_HOSTS "
                "where that server runs)")
    finally:
        srv.shutdown()


def _deep(levels: int) -> bytes:
    return (b"<?xml version='1.0'?><methodResponse><params><param><value>"
            + b"<array><data><value>" * levels + b"<int>1</int>" + b"</value></data></array>" * levels
            + b"</value></param></params></methodResponse>")


def _answering(reply: bytes):
    """A server that reads one request and sends ``reply`` (raw bytes), then closes."""
    listener = socket.create_server(("127.0.0.1", 0))

    def answer() -> None:
        conn, _ = listener.accept()
        with conn:
            conn.recv(65536)
            conn.sendall(reply)

    thread = threading.Thread(target=answer, daemon=True)
    thread.start()
    return listener, thread


def _http(body: bytes) -> bytes:
    return b"HTTP/1.1 200 OK\r\nContent-Type: text/xml\r\nContent-Length: %d\r\n\r\n%s" % (len(body), body)


@pytest.mark.parametrize("reply,reason", [
    (_http(b"garbage \x00\xff"), "a reply that is not XML-RPC (syntax error: line 1, column 0)"),
    (_http(b'<?xml version="1.0"?><!DOCTYPE m [<!ENTITY a "b">]><methodResponse><params><param>'
           b"<value>&a;</value></param></params></methodResponse>"),
     "a reply that is not XML-RPC (XML document type declarations and entities are not allowed)"),
    (_http(_deep(100_000)), "a reply that is not XML-RPC (arrays and structs nested more than 200 deep)"),
    (_http(b"<html><body>a web server</body></html>"),
     "a reply that is not XML-RPC (no methodResponse value in it)"),
    (b"SSH-2.0-OpenSSH_9.2\r\n", "a bad reply: not HTTP: b'SSH-2.0-OpenSSH_9.2\\r\\n'"),
])
def test_a_reply_that_is_not_xmlrpc_is_one_line(reply: bytes, reason: str):
    listener, thread = _answering(reply)
    address = f"http://127.0.0.1:{listener.getsockname()[1]}/"
    try:
        with pytest.raises(mx.BadReply) as info:
            mx.ServerProxy(address, timeout=5).add(1, 2)
    finally:
        thread.join(5)
        listener.close()
    assert str(info.value) == f"{address} sent {reason}"
    # what code catching Python's own exceptions expects
    assert isinstance(info.value, (xmlrpc.client.ProtocolError, xmlrpc.client.ResponseError))


def test_nesting_is_bounded_and_deep_enough_for_any_parameter():
    listener, thread = _answering(_http(_deep(mx.MAX_REPLY_DEPTH)))
    try:
        value = mx.ServerProxy(f"http://127.0.0.1:{listener.getsockname()[1]}/", timeout=5).add(1, 2)
    finally:
        thread.join(5)
        listener.close()
    for _ in range(mx.MAX_REPLY_DEPTH):
        (value,) = value
    assert value == 1
    mx.check_nesting(b"<struct><array></array><array><struct></struct></array></struct>", 3)
    with pytest.raises(ValueError, match="nested more than 2 deep"):
        mx.check_nesting(b"<struct><array></array><array><struct></struct></array></struct>", 2)
