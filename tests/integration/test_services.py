"""minros services end to end on minros's master: the TCPROS service exchange byte by byte,
ServiceProxy and wait_for_service semantics, Service.shutdown, concurrency.

Servers run as subprocesses (one node per process); the clients run in this process without
init_node, as rospy allows.
"""

from __future__ import annotations

import socket
import struct
import threading
import time
import xmlrpc.client
from pathlib import Path

import pytest

import minros
from minros.client.services import parse_rosrpc_uri
from minros.exceptions import ROSException, ServiceException
from minros.wire import tcpros
from services_support import ADD_TWO_INTS_MD5, SERVER
from support import PYTHON, Proc, ros_env


@pytest.fixture
def master_env(minros_master: int, ros_home: Path, monkeypatch):
    env = ros_env(minros_master, ros_home)
    monkeypatch.setenv("ROS_MASTER_URI", env["ROS_MASTER_URI"])
    return env


@pytest.fixture
def adder(master_env, tmp_path: Path):
    """The shared test server (tests/services_support.py SERVER) as node /adder."""
    script = tmp_path / "server.py"
    script.write_text(SERVER)
    proc = Proc([PYTHON, str(script), "adder"], master_env)
    proc.read_until("READY", 30)
    yield proc
    proc.stop()


def service_address(env, name: str = "/add_two_ints"):
    master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
    code, msg, uri = master.lookupService("/tester", name)
    assert code == 1, msg
    return parse_rosrpc_uri(uri)


def connect(env, name: str = "/add_two_ints") -> socket.socket:
    sock = socket.create_connection(service_address(env, name), timeout=10)
    return sock


def recv_exact(sock: socket.socket, size: int) -> bytes:
    data = b""
    while len(data) < size:
        chunk = sock.recv(size - len(data))
        assert chunk, f"connection closed after {len(data)} of {size} bytes"
        data += chunk
    return data


def read_header(sock: socket.socket) -> dict:
    (size,) = struct.unpack("<I", recv_exact(sock, 4))
    return tcpros.decode_header(recv_exact(sock, size))


def assert_closed(sock: socket.socket) -> None:
    assert sock.recv(1) == b""


def request(a: int, b: int) -> bytes:
    return tcpros.encode_frame(struct.pack("<qq", a, b))


def read_response(sock: socket.socket):
    ok, size = struct.unpack("<BI", recv_exact(sock, 5))
    return ok, recv_exact(sock, size)


HEADER = {"service": "/add_two_ints", "md5sum": ADD_TWO_INTS_MD5, "callerid": "/tester"}


# ---------------------------------------------------------------------------- wire

def test_wire_exchange_is_tcpros(adder, master_env):
    with connect(master_env) as sock:
        sock.sendall(tcpros.encode_header(HEADER))
        assert read_header(sock) == {"callerid": "/adder", "md5sum": ADD_TWO_INTS_MD5,
                                     "service": "/add_two_ints",
                                     "type": "rospy_tutorials/AddTwoInts"}
        sock.sendall(request(2, 3))
        assert recv_exact(sock, 13) == b"\x01" + struct.pack("<I", 8) + struct.pack("<q", 5)
        assert_closed(sock)  # not persistent: one request per connection


def test_wire_persistent_connection_serves_many_requests(adder, master_env):
    with connect(master_env) as sock:
        sock.sendall(tcpros.encode_header({**HEADER, "persistent": "1"}))
        read_header(sock)
        for i in range(5):
            sock.sendall(request(i, 100))
            assert read_response(sock) == (1, struct.pack("<q", i + 100))
        # two requests in one write: answered in order
        sock.sendall(request(1, 1) + request(2, 2))
        assert read_response(sock) == (1, struct.pack("<q", 2))
        assert read_response(sock) == (1, struct.pack("<q", 4))


def test_wire_probe_gets_header_then_close(adder, master_env):
    with connect(master_env) as sock:
        sock.sendall(tcpros.encode_header({"probe": "1", "md5sum": "*", "callerid": "/tester",
                                           "service": "/add_two_ints"}))
        assert read_header(sock)["type"] == "rospy_tutorials/AddTwoInts"
        assert_closed(sock)


def test_wire_md5_mismatch_and_wildcard(adder, master_env):
    with connect(master_env) as sock:
        sock.sendall(tcpros.encode_header({**HEADER, "md5sum": "0" * 32}))
        assert read_header(sock) == {
            "error": f"request from [/tester]: md5sums do not match: [{'0' * 32}] vs. [{ADD_TWO_INTS_MD5}]"}
        assert_closed(sock)
    with connect(master_env) as sock:
        sock.sendall(tcpros.encode_header({**HEADER, "md5sum": "*"}))
        assert read_header(sock)["md5sum"] == ADD_TWO_INTS_MD5
        sock.sendall(request(1, 2))
        assert read_response(sock) == (1, struct.pack("<q", 3))


def test_wire_missing_field(adder, master_env):
    with connect(master_env) as sock:
        sock.sendall(tcpros.encode_header({"service": "/add_two_ints", "md5sum": "*"}))
        assert read_header(sock) == {"error": "Missing required 'callerid' field"}


def test_wire_handler_errors_are_ok0_strings(adder, master_env):
    for a, text in ((13, "service cannot process request: unlucky number"),
                    (14, "error processing request: boom"),
                    (15, "service cannot process request: service handler returned None")):
        with connect(master_env) as sock:
            sock.sendall(tcpros.encode_header(HEADER))
            read_header(sock)
            sock.sendall(request(a, 0))
            assert read_response(sock) == (0, text.encode())
            assert_closed(sock)
    assert "error handler saw boom" in adder.read_until("error handler saw boom", 10)


def test_wire_garbage_closes_only_that_connection(adder, master_env):
    with connect(master_env) as sock:
        sock.sendall(tcpros.encode_header({**HEADER, "persistent": "1"}))
        read_header(sock)
        sock.sendall(b"\xff\xff\xff\xff")  # a 4 GiB request: refused, nothing allocated
        assert_closed(sock)
    with connect(master_env) as sock:
        sock.sendall(tcpros.encode_header(HEADER))
        read_header(sock)
        sock.sendall(struct.pack("<I", 16) + b"\x01\x02")  # cut short, then hang up
        sock.shutdown(socket.SHUT_WR)
        assert_closed(sock)
    proxy = minros.ServiceProxy("/add_two_ints", _srv())
    assert proxy(5, 5).sum == 10  # the server is unharmed


# ---------------------------------------------------------------------------- ServiceProxy

def _srv():
    from rospy_tutorials.srv import AddTwoInts

    return AddTwoInts


def test_proxy_call_styles_and_connection_header(adder, master_env):
    from rospy_tutorials.srv import AddTwoIntsRequest, AddTwoIntsResponse

    proxy = minros.ServiceProxy("add_two_ints", _srv(), headers={"cookies": "chocolate"})
    assert proxy.resolved_name == "/add_two_ints"
    r1 = proxy(1, 2)
    assert isinstance(r1, AddTwoIntsResponse) and r1.sum == 3
    assert proxy.call(AddTwoIntsRequest(3, 4)).sum == 7
    assert proxy(a=5, b=6).sum == 11
    assert proxy(AddTwoIntsRequest(a=-7, b=2)).sum == -5
    assert r1._connection_header["callerid"] == "/adder"
    with pytest.raises(TypeError):
        proxy(1, 2, c=3)
    with pytest.raises(TypeError):
        proxy.call(_srv()._response_class(1))  # a message of another type


def test_proxy_persistent_reuses_one_connection(adder, master_env):
    proxy = minros.ServiceProxy("/add_two_ints", _srv(), persistent=True)
    try:
        assert [proxy(i + 100, 1).sum for i in range(20)] == [i + 101 for i in range(20)]
        first_end = proxy._end
        proxy(0, 0)
        assert proxy._end is first_end and first_end is not None
    finally:
        proxy.close()
    assert proxy._end is None


@pytest.mark.smoke
def test_proxy_errors(adder, master_env, monkeypatch):
    with pytest.raises(ServiceException, match=r"^service \[/nope\] unavailable$"):
        minros.ServiceProxy("/nope", _srv())(1, 2)
    with pytest.raises(ServiceException) as info:
        minros.ServiceProxy("/add_two_ints", _srv())(13, 0)
    assert str(info.value) == ("service [/add_two_ints] responded with an error: "
                               "b'service cannot process request: unlucky number'")
    from rospy_tutorials.srv import BadTwoInts

    with pytest.raises(ServiceException) as info:
        minros.ServiceProxy("/add_two_ints", BadTwoInts)(1, 2)
    assert str(info.value).startswith(
        "unable to connect to service: remote error reported: request from [")
    assert "md5sums do not match" in str(info.value)
    from support import free_port

    monkeypatch.setenv("ROS_MASTER_URI", f"http://127.0.0.1:{free_port()}")
    with pytest.raises(ServiceException, match="^unable to contact master$"):
        minros.ServiceProxy("/add_two_ints", _srv())(1, 2)


def test_concurrent_clients(adder, master_env):
    errors: list = []

    def worker(k: int) -> None:
        proxy = minros.ServiceProxy("/add_two_ints", _srv(), persistent=(k % 2 == 0))
        try:
            for i in range(15):
                assert proxy(k + 100, i).sum == k + 100 + i
        except Exception as exc:  # noqa: BLE001 - collected for the assertion below
            errors.append(exc)
        finally:
            proxy.close()

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    assert not errors and not any(t.is_alive() for t in threads)


# ---------------------------------------------------------------------------- wait_for_service

def test_wait_for_service_arguments_and_timeout(master_env):
    with pytest.raises(ValueError, match="timeout must be non-zero"):
        minros.wait_for_service("/nope", timeout=0)
    start = time.monotonic()
    with pytest.raises(ROSException, match=r"^timeout exceeded while waiting for service /nope$"):
        minros.wait_for_service("nope", timeout=0.5)
    elapsed = time.monotonic() - start
    assert 0.45 <= elapsed < 5.0
    with pytest.raises(ROSException):
        minros.wait_for_service("/nope", timeout=minros.Duration(0, 300_000_000))


def test_wait_for_service_returns_once_the_service_appears(master_env, tmp_path):
    result: dict = {}

    def wait() -> None:
        try:
            minros.wait_for_service("/add_two_ints", timeout=30)
            result["ok"] = time.monotonic()
        except Exception as exc:  # noqa: BLE001
            result["error"] = exc

    waiter = threading.Thread(target=wait)
    waiter.start()
    script = tmp_path / "server.py"
    script.write_text(SERVER)
    proc = Proc([PYTHON, str(script), "late_adder"], master_env)
    try:
        proc.read_until("READY", 30)
        ready_at = time.monotonic()
        waiter.join(30)
        assert "ok" in result, result
        assert result["ok"] - ready_at < 5.0  # polling every 0.3 s, not the 30 s timeout
        assert minros.ServiceProxy("/add_two_ints", _srv())(1, 1).sum == 2
    finally:
        proc.stop()


SHUTDOWN_SERVER = r'''
import rospy
from std_srvs.srv import Empty, EmptyResponse
rospy.init_node("shutter")
target = rospy.Service("target", Empty, lambda req: EmptyResponse())
try:
    rospy.Service("/target", Empty, lambda req: EmptyResponse())
except rospy.ServiceException as e:
    print("DUPLICATE %s" % e, flush=True)
def stop(req):
    target.shutdown("asked to")
    return EmptyResponse()
rospy.Service("stop_target", Empty, stop)
print("READY %s" % target.uri, flush=True)
rospy.spin()
'''


def test_service_shutdown_unregisters(master_env, tmp_path):
    from std_srvs.srv import Empty

    script = tmp_path / "shutter.py"
    script.write_text(SHUTDOWN_SERVER)
    proc = Proc([PYTHON, str(script)], master_env)
    try:
        out = proc.read_until("READY", 30)
        assert "DUPLICATE service [/target] already registered" in out
        minros.wait_for_service("/target", timeout=10)
        master = xmlrpc.client.ServerProxy(master_env["ROS_MASTER_URI"])
        code, _msg, uri = master.lookupService("/tester", "/target")
        assert f"READY {uri}" in out  # Service.uri is what the master hands out
        minros.ServiceProxy("/target", Empty)()
        minros.ServiceProxy("/stop_target", Empty)()
        with pytest.raises(ServiceException, match=r"service \[/target\] unavailable"):
            minros.ServiceProxy("/target", Empty)()
        code, _msg, _uri = master.lookupService("/tester", "/target")
        assert code == -1
        assert minros.ServiceProxy("/stop_target", Empty)() is not None
    finally:
        proc.stop()


DYING_SERVER = r'''
import os
import rospy
from std_srvs.srv import Empty
rospy.init_node("dier")
rospy.Service("die", Empty, lambda req: os._exit(0))
print("READY", flush=True)
rospy.spin()
'''


def test_server_dying_mid_call(master_env, tmp_path):
    from std_srvs.srv import Empty

    script = tmp_path / "dier.py"
    script.write_text(DYING_SERVER)
    proc = Proc([PYTHON, str(script)], master_env)
    try:
        proc.read_until("READY", 30)
        minros.wait_for_service("/die", timeout=10)
        with pytest.raises(ServiceException) as info:
            minros.ServiceProxy("/die", Empty)()
        # rospy's words, checked against Debian's rospy by hand
        assert str(info.value) == ("transport error completing service call: unable to receive "
                                   "data from sender, check sender's logs for details")
    finally:
        proc.stop()


BIG_SERVER = r'''
import rospy
from sensor_msgs.srv import SetCameraInfo, SetCameraInfoResponse
def handle(req):
    d = req.camera_info.D
    return SetCameraInfoResponse(True, "%d %s %s" % (len(d), d[0], d[-1]) + "x" * 3000000)
rospy.init_node("big_server")
rospy.Service("set_camera_info", SetCameraInfo, handle, buff_size=1024)
print("READY", flush=True)
rospy.spin()
'''


def test_big_request_and_response(master_env, tmp_path):
    from sensor_msgs.msg import CameraInfo
    from sensor_msgs.srv import SetCameraInfo

    script = tmp_path / "big.py"
    script.write_text(BIG_SERVER)
    proc = Proc([PYTHON, str(script)], master_env)
    try:
        proc.read_until("READY", 30)
        minros.wait_for_service("/set_camera_info", timeout=10)
        d = [0.25] * 1_000_000  # 8 MB of float64 in the request
        d[-1] = 7.5
        proxy = minros.ServiceProxy("/set_camera_info", SetCameraInfo)
        response = proxy(CameraInfo(D=d))
        assert response.success
        assert response.status_message == "1000000 0.25 7.5" + "x" * 3000000
    finally:
        proc.stop()


def test_silent_server_times_out_the_handshake(master_env, monkeypatch):
    """A peer that accepts but never sends its header cannot hang the caller."""
    from minros.client import services

    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(1)
        port = listener.getsockname()[1]
        master = xmlrpc.client.ServerProxy(master_env["ROS_MASTER_URI"])
        code, msg, _ = master.registerService("/silent_node", "/silent", f"rosrpc://127.0.0.1:{port}",
                                              "http://127.0.0.1:1/")
        assert code == 1, msg
        monkeypatch.setattr(services, "CONNECT_TIMEOUT", 0.3)
        start = time.monotonic()
        with pytest.raises(ServiceException) as info:
            minros.ServiceProxy("/silent", _srv())(1, 2)
        assert time.monotonic() - start < 5
        assert str(info.value) == ("unable to connect to service: "
                                   "timed out waiting for the connection header")


def test_parse_rosrpc_uri():
    assert parse_rosrpc_uri("rosrpc://host:1234") == ("host", 1234)
    assert parse_rosrpc_uri("rosrpc://10.0.0.1:99/extra") == ("10.0.0.1", 99)
    from minros.client.services import ParameterInvalid

    for bad in ("http://host:1", "rosrpc://host", "rosrpc://host:x", "rosrpc://a:1:2"):
        with pytest.raises(ParameterInvalid):
            parse_rosrpc_uri(bad)
