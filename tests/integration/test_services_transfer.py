"""Big service requests and responses against slow, stalled and vanishing peers.

The service sockets block; node shutdown wakes a call waiting for its response by shutting
its socket down, and a send to a peer that reads nothing waits ``_POLL`` seconds at a time to
notice node shutdown; a send must not take that as a limit: it goes on while the peer takes bytes, however slowly (rospy waits
forever), and gives up only when the node shuts down, the peer is gone, or the peer took
nothing for ``SEND_STALL_TIMEOUT`` seconds. The slow peers here are raw sockets doing the
TCPROS service exchange by hand, reading in small chunks with pauses: the pauses are the
scenario (a peer busy elsewhere), not synchronisation.
"""

from __future__ import annotations

import hashlib
import os
import signal
import socket
import struct
import threading
import time
import xmlrpc.client
from pathlib import Path

import pytest

import minros
from minros.client import services
from minros.exceptions import ServiceException
from minros.transport import tcpros_service
from minros.wire import tcpros
from support import PYTHON, Proc, ros_env

#: bytes a slow peer takes per recv (and its receive buffer), so the sender really waits
CHUNK = 64 * 1024


@pytest.fixture
def master_env(minros_master: int, ros_home: Path, monkeypatch):
    env = ros_env(minros_master, ros_home)
    monkeypatch.setenv("ROS_MASTER_URI", env["ROS_MASTER_URI"])
    return env


def recv_exact(sock: socket.socket, size: int) -> bytearray:
    data = bytearray(size)
    view = memoryview(data)
    got = 0
    while got < size:
        n = sock.recv_into(view[got:], min(size - got, CHUNK))
        assert n, f"connection closed after {got} of {size} bytes"
        got += n
    return data


def recv_slowly(sock: socket.socket, size: int, first_pause: float, pause: float, every: int) -> bytes:
    """``size`` bytes in CHUNK pieces: a ``first_pause`` after the first piece (longer than the
    sender's poll interval), then ``pause`` after every ``every`` bytes."""
    data = bytearray(size)
    view = memoryview(data)
    got = 0
    paused_first = False
    while got < size:
        n = sock.recv_into(view[got:], min(size - got, CHUNK))
        assert n, f"connection closed after {got} of {size} bytes"
        if not paused_first:
            paused_first = True
            time.sleep(first_pause)
        elif (got + n) // every != got // every:
            time.sleep(pause)
        got += n
    return bytes(data)


def read_header(sock: socket.socket) -> dict:
    (size,) = struct.unpack("<I", recv_exact(sock, 4))
    return tcpros.decode_header(bytes(recv_exact(sock, size)))


def small_receive_buffer(sock: socket.socket) -> socket.socket:
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, CHUNK)
    return sock


# ---------------------------------------------------------------------- a minros server sending

BIG_RESPONSE_SERVER = r'''
import hashlib
import os
import sys
import rospy
from sensor_msgs.srv import SetCameraInfo, SetCameraInfoResponse
from std_srvs.srv import Trigger, TriggerResponse

# random hex, so a lost, repeated or reordered piece changes the digest
MESSAGE = os.urandom(int(sys.argv[1]) // 2).hex()
print("SHA256 %s" % hashlib.sha256(MESSAGE.encode()).hexdigest(), flush=True)
served = 0

def handle(req):
    global served
    served += 1
    print("SERVING %d" % served, flush=True)
    return TriggerResponse(True, MESSAGE)

def count(req):  # a request over 16 MB: the reader grows its buffer while receiving
    d = req.camera_info.D
    return SetCameraInfoResponse(True, "%d %s %s" % (len(d), d[1], d[-1]))

rospy.init_node("big_responder")
rospy.Service("big", Trigger, handle)
rospy.Service("count_d", SetCameraInfo, count)
print("READY", flush=True)
rospy.spin()
'''

RESPONSE_SIZE = 30_000_000


@pytest.fixture
def big_responder(master_env, tmp_path: Path):
    """A minros node serving /big (std_srvs/Trigger) with a RESPONSE_SIZE-byte message;
    yields (proc, sha256 of the message, the output read so far)."""
    script = tmp_path / "big_responder.py"
    script.write_text(BIG_RESPONSE_SERVER)
    proc = Proc([PYTHON, str(script), str(RESPONSE_SIZE)], master_env)
    try:
        out = proc.read_until("READY", 30)
        digest = out.split("SHA256 ", 1)[1].split()[0]
        yield proc, digest, out
    finally:
        proc.stop()


def open_trigger(env) -> socket.socket:
    """A raw client connection to /big, past the handshake, with the request sent."""
    from std_srvs.srv import Trigger

    master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
    code, msg, uri = master.lookupService("/tester", "/big")
    assert code == 1, msg
    sock = small_receive_buffer(socket.socket())
    sock.settimeout(20)
    sock.connect(services.parse_rosrpc_uri(uri))
    sock.sendall(tcpros.encode_header({"service": "/big", "md5sum": Trigger._md5sum,
                                       "callerid": "/slow_reader"}))
    assert read_header(sock)["type"] == "std_srvs/Trigger"
    sock.sendall(tcpros.encode_frame(b""))  # Trigger's request has no fields
    return sock


def test_big_response_reaches_a_slow_reader(big_responder, master_env):
    proc, digest, _ = big_responder
    with open_trigger(master_env) as sock:
        start = time.monotonic()
        ok, size = struct.unpack("<BI", recv_exact(sock, 5))
        assert ok == 1
        body = recv_slowly(sock, size, first_pause=1.5, pause=0.1, every=3_000_000)
        elapsed = time.monotonic() - start
        assert sock.recv(1) == b""  # not persistent: the server closes after the response
    (success, length) = struct.unpack_from("<BI", body)
    assert success == 1 and length == RESPONSE_SIZE == size - 5
    assert hashlib.sha256(body[5:]).hexdigest() == digest
    assert elapsed > 2.0  # the reader really was slow (longer than the sender's 1 s poll)
    assert "incoming connection failed" not in proc.stop()


def test_requests_and_responses_over_16_mb_between_minros_nodes(big_responder, master_env):
    """Frames bigger than the reader's first big-frame buffer (16 MB), both ways."""
    from sensor_msgs.srv import SetCameraInfo
    from std_srvs.srv import Trigger

    proc, digest, _ = big_responder
    response = minros.ServiceProxy("/big", Trigger)()
    assert hashlib.sha256(response.message.encode()).hexdigest() == digest
    count = 2_500_000  # 20 MB of float64
    response = minros.ServiceProxy("/count_d", SetCameraInfo)(camera_info_request(count))
    assert response.status_message == f"{count} 1.0 {count - 1.0}"
    assert "Traceback" not in proc.stop()


def test_reader_that_stops_and_leaves_costs_one_log_line(big_responder, master_env):
    from std_srvs.srv import Trigger

    proc, digest, seen = big_responder
    sock = open_trigger(master_env)
    try:
        assert recv_exact(sock, 5)[0] == 1  # the response started...
        recv_exact(sock, CHUNK)
    finally:
        sock.close()  # ...and we leave with unread bytes: the server's sends fail (RST)
    seen += proc.read_until("not delivered", 15)
    response = minros.ServiceProxy("/big", Trigger)()  # the server is still healthy
    assert hashlib.sha256(response.message.encode()).hexdigest() == digest
    seen += proc.read_until("SERVING 2", 15)
    seen += proc.stop()
    failures = [line for line in seen.splitlines() if "incoming connection failed" in line]
    assert len(failures) == 1, seen
    assert "[/big] response to [/slow_reader] not delivered" in failures[0]
    assert "Traceback" not in seen


# ---------------------------------------------------------------------- a minros client sending

class RawServer:
    """A service server on a raw socket, registered on the master as /raw_camera_info
    (sensor_msgs/SetCameraInfo). ``serve(sock)`` runs once per connection, after the handshake."""

    def __init__(self, env, serve) -> None:
        from sensor_msgs.srv import SetCameraInfo

        self.srv = SetCameraInfo
        self.serve = serve
        self.error: BaseException | None = None
        self.listener = small_receive_buffer(socket.socket())
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(4)
        self.listener.settimeout(20)
        port = self.listener.getsockname()[1]
        self.master = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
        code, msg, _ = self.master.registerService("/raw_server", "/raw_camera_info",
                                                   f"rosrpc://127.0.0.1:{port}", "http://127.0.0.1:1/")
        assert code == 1, msg
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        try:
            sock, _ = self.listener.accept()
            with sock:
                sock.settimeout(20)
                header = read_header(sock)
                assert header["service"] == "/raw_camera_info"
                sock.sendall(tcpros.encode_header({
                    "service": "/raw_camera_info", "type": self.srv._type,
                    "md5sum": self.srv._md5sum, "callerid": "/raw_server"}))
                self.serve(sock)
        except BaseException as exc:  # reported by join()
            self.error = exc

    def join(self) -> None:
        self.thread.join(30)
        assert not self.thread.is_alive()
        self.listener.close()
        if self.error is not None:
            raise self.error


def camera_info_request(count: int):
    from sensor_msgs.msg import CameraInfo

    d = [float(i) for i in range(count)]  # every value differs: order and content both checked
    return CameraInfo(D=d)


def test_big_request_reaches_a_slow_server(master_env, monkeypatch):
    """A 16 MB request to a server that reads it over ~2.5 s, pausing longer than the
    sender's poll interval, with a stall bound shorter than the whole transfer: progress
    keeps the send going."""
    from sensor_msgs.srv import SetCameraInfo

    monkeypatch.setattr(tcpros_service, "POLL", 0.2)
    monkeypatch.setattr(tcpros_service, "SEND_STALL_TIMEOUT", 1.0)
    count = 2_000_000
    got = {}

    def serve(sock: socket.socket) -> None:
        (size,) = struct.unpack("<I", recv_exact(sock, 4))
        start = time.monotonic()
        body = recv_slowly(sock, size, first_pause=0.5, pause=0.5, every=4_000_000)
        got["elapsed"] = time.monotonic() - start
        request = SetCameraInfo._request_class().deserialize(body)
        d = request.camera_info.D
        ok = len(d) == count and all(d[i] == float(i) for i in range(0, count, 997)) and d[-1] == count - 1
        response = SetCameraInfo._response_class(ok, f"{len(d)} values")
        payload = response.serialize_to_bytes()
        sock.sendall(struct.pack("<BI", 1, len(payload)) + payload)

    server = RawServer(master_env, serve)
    try:
        response = minros.ServiceProxy("/raw_camera_info", SetCameraInfo)(camera_info_request(count))
    finally:
        server.join()
    assert response.status_message == f"{count} values"
    assert response.success
    assert got["elapsed"] > 2.0  # slower than the stall bound: only progress kept it going


def test_stalled_server_is_given_up_after_the_stall_timeout(master_env, monkeypatch):
    """A server that takes the handshake and then no request byte: the call fails once
    SEND_STALL_TIMEOUT passes without progress, not at the first poll and not never."""
    from sensor_msgs.srv import SetCameraInfo

    monkeypatch.setattr(tcpros_service, "POLL", 0.2)
    monkeypatch.setattr(tcpros_service, "SEND_STALL_TIMEOUT", 1.0)
    done = threading.Event()

    def serve(sock: socket.socket) -> None:
        recv_exact(sock, CHUNK)  # the request started, then nothing more is read
        done.wait(20)

    server = RawServer(master_env, serve)
    start = time.monotonic()
    try:
        with pytest.raises(ServiceException) as info:
            # 32 MB: more than both kernel buffers hold, so the sender must wait
            minros.ServiceProxy("/raw_camera_info", SetCameraInfo)(camera_info_request(4_000_000))
        elapsed = time.monotonic() - start
    finally:
        done.set()
        server.join()
    assert str(info.value) == "transport error completing service call: peer took no data for 1 s"
    assert 1.0 <= elapsed < 6.0


STALLED_CALLER = r'''
import sys
import threading
import time
import rospy
from sensor_msgs.msg import CameraInfo
from sensor_msgs.srv import SetCameraInfo

rospy.init_node("stalled_caller")
result = {}

def call():
    try:
        rospy.ServiceProxy("/raw_camera_info", SetCameraInfo)(CameraInfo(D=[0.5] * 4000000))
        result["outcome"] = "returned"
    except Exception as e:
        result["outcome"] = "%s: %s" % (type(e).__name__, e)
    result["at"] = time.monotonic()

caller = threading.Thread(target=call)
caller.start()
print("CALLING", flush=True)
rospy.spin()
stopped = time.monotonic()
caller.join(10)
print("RESULT %s | after shutdown %.2f s" % (result.get("outcome"), result.get("at", 1e9) - stopped), flush=True)
'''


def test_node_shutdown_interrupts_a_stalled_send(master_env, tmp_path):
    """rospy.spin() returns on SIGINT; the call blocked sending to a server that reads
    nothing ends within about a poll interval with ROSInterruptException."""
    done = threading.Event()
    started = threading.Event()

    def serve(sock: socket.socket) -> None:
        recv_exact(sock, CHUNK)
        started.set()
        done.wait(20)

    server = RawServer(master_env, serve)
    script = tmp_path / "stalled_caller.py"
    script.write_text(STALLED_CALLER)
    proc = Proc([PYTHON, str(script)], master_env)
    try:
        proc.read_until("CALLING", 30)
        assert started.wait(20)
        os.killpg(proc.pid, signal.SIGINT)
        out = proc.read_until("RESULT", 15)
    finally:
        done.set()
        proc.stop()
        server.join()
    line = out.split("RESULT ", 1)[1].splitlines()[0]
    outcome, after = line.split(" | after shutdown ")
    assert outcome == "ROSInterruptException: node shutdown interrupted service call"
    assert -1.0 < float(after.split()[0]) < 3.0


WAITING_CALLER = STALLED_CALLER.replace("CameraInfo(D=[0.5] * 4000000)", "CameraInfo(D=[0.5] * 4)")


def test_node_shutdown_interrupts_a_call_waiting_for_its_response(master_env, tmp_path):
    """The request is sent whole and the server never answers: the call, blocked in recv
    (no socket timeout wakes it), ends at SIGINT with ROSInterruptException."""
    done = threading.Event()
    started = threading.Event()

    def serve(sock: socket.socket) -> None:
        (size,) = struct.unpack("<I", recv_exact(sock, 4))
        recv_exact(sock, size)  # the whole request: the caller now waits for the response
        started.set()
        done.wait(20)

    server = RawServer(master_env, serve)
    script = tmp_path / "waiting_caller.py"
    script.write_text(WAITING_CALLER)
    proc = Proc([PYTHON, str(script)], master_env)
    try:
        proc.read_until("CALLING", 30)
        assert started.wait(20)
        os.killpg(proc.pid, signal.SIGINT)
        out = proc.read_until("RESULT", 15)
    finally:
        done.set()
        proc.stop()
        server.join()
    line = out.split("RESULT ", 1)[1].splitlines()[0]
    outcome, after = line.split(" | after shutdown ")
    assert outcome == "ROSInterruptException: node shutdown interrupted service call"
    assert -1.0 < float(after.split()[0]) < 3.0
