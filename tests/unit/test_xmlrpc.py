"""minros.wire.xmlrpc: dispatch, faults, keep-alive, limits and hostile clients (loopback sockets)."""

from __future__ import annotations

import socket
import threading
import time
import xmlrpc.client

import pytest

from minros.wire import xmlrpc as mx


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
        mx_wait = time.monotonic() + 3
        while srv.connection_count() and time.monotonic() < mx_wait:
            time.sleep(0.02)
        assert srv.connection_count() == 0
        assert proxy.add(2, 2) == 4
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
        assert time.monotonic() - start < 2.0
    finally:
        for s in silent:
            s.close()


def test_connection_bound_reclaims_idle_connections():
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", idle_timeout=30, max_connections=2).start()
    try:
        silent = [socket.create_connection(("127.0.0.1", srv.port), timeout=5) for _ in range(2)]
        wait = time.monotonic() + 3
        while srv.connection_count() < 2 and time.monotonic() < wait:
            time.sleep(0.01)
        proxy = mx.ServerProxy(f"http://127.0.0.1:{srv.port}/", timeout=5)
        start = time.monotonic()
        assert proxy.add(1, 2) == 3  # served at once: an idle connection was closed for it
        assert time.monotonic() - start < 2.0
        assert silent[0].recv(10) == b""  # the longest-idle one
        assert srv.connection_count() <= 2
        # a kept-alive client whose connection gets reclaimed simply reconnects
        other = mx.ServerProxy(f"http://127.0.0.1:{srv.port}/", timeout=5)
        for i in range(5):
            assert other.add(i, 1) == i + 1
            assert proxy.add(i, 2) == i + 2
        for s in silent:
            s.close()
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


def test_bodies_in_memory_are_bounded_in_total():
    srv = mx.XmlRpcServer(Handler(), "127.0.0.1", max_body=1000, body_budget=1000, idle_timeout=0.1)
    assert srv._reserve(900)
    start = time.monotonic()
    assert not srv._reserve(200)  # would exceed the budget: refused after a short wait
    assert time.monotonic() - start >= 0.09
    srv._release(900)
    assert srv._reserve(200)
    srv._release(200)
    # and the server still answers requests through the budget
    srv.start()
    try:
        assert mx.ServerProxy(f"http://127.0.0.1:{srv.port}/").add(1, 2) == 3
        assert srv._budget_used == 0
    finally:
        srv.shutdown()


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
