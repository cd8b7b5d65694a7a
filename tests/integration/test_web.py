"""``minros web`` with real clients: roslibpy (PyPI), Foxglove's own client libraries (npm:
@foxglove/ws-protocol + @foxglove/rosmsg-serialization, run by node), roslib (npm) in headless
Chromium; web_video_server's endpoints; the seed's video subscriber under headless OpenCV; bad
input from a raw WebSocket client; the launch files of rosbridge_server and foxglove_bridge.

The node clients need ``npm ci`` in tests/web/js and Chromium needs Debian's ``chromium``
(scripts/install-ros-reference.sh installs it): missing, they skip locally and fail in CI.
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import threading
import time
import urllib.error
import urllib.request
import xmlrpc.client
from pathlib import Path

import cv2
import numpy as np
import pytest

from support import (
    CHROMIUM,
    EXAMPLES,
    PYTHON,
    Proc,
    free_port,
    launch_chromium,
    need,
    ros_env,
    wait_for_master,
)

WEB = Path(__file__).resolve().parent.parent / "web"
JS = WEB / "js"
VIDEO = EXAMPLES / "video"
#: the test-only fake webcam shim (a synthetic camera for video_pub.py)
FAKECAM = Path(__file__).resolve().parent.parent / "examples" / "fakecam"


def start_web(port: int, home: Path, *args: str, web_port: int | None = None,
              env: dict | None = None) -> tuple:
    web_port = web_port or free_port()
    proc = Proc([PYTHON, "-m", "minros", "web", "--port", str(web_port), *args],
                ros_env(port, home, env))
    proc.read_until("listening on", timeout=20)
    return proc, web_port


class Graph:
    """minros core + turtlesim + a talker + minros web, shared by the tests of this module."""

    def __init__(self, tmp: Path) -> None:
        self.home = tmp / "ros_home"
        (self.home / "log").mkdir(parents=True)
        self.port = free_port()
        self.procs = [Proc([PYTHON, "-m", "minros", "core", "-p", str(self.port)], self.env())]
        wait_for_master(self.port)
        turtle = Proc([PYTHON, "-m", "minros", "run", "turtlesim", "turtlesim_node"],
                      self.env({"MINROS_HEADLESS": "1"}))
        self.procs.append(turtle)
        turtle.read_until("Spawning turtle [turtle1]", timeout=20)
        self.procs.append(Proc([PYTHON, "-m", "minros", "topic", "pub", "-r", "10", "/chatter",
                                "std_msgs/String", "data: hello web"], self.env()))
        self.web, self.web_port = start_web(self.port, self.home)
        self.procs.append(self.web)

    def env(self, extra: dict | None = None) -> dict:
        return ros_env(self.port, self.home, extra)

    @property
    def ws(self) -> str:
        return f"ws://127.0.0.1:{self.web_port}"

    @property
    def http(self) -> str:
        return f"http://127.0.0.1:{self.web_port}"

    def stop(self) -> str:
        out = ""
        for proc in reversed(self.procs):
            out += proc.stop()
        return out


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    g = Graph(tmp_path_factory.mktemp("web"))
    try:
        yield g
    finally:
        g.stop()


def node_client(*args: str, timeout: float = 30, env: dict | None = None,
                check: bool = True) -> list:
    need(shutil.which("node") is not None and (JS / "node_modules" / "@foxglove").is_dir(),
         "node and tests/web/js/node_modules (npm ci) are needed for the Foxglove client")
    done = subprocess.run(["node", str(JS / "foxglove_client.mjs"), *args], capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, **(env or {})})
    lines = [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]
    assert done.returncode == 0 or not check, f"{done.stdout}\n{done.stderr}"
    return lines


# -- roslibpy --------------------------------------------------------------------------------

def test_roslibpy_subscribes_publishes_calls_and_uses_rosapi(graph):
    proc = Proc([PYTHON, str(WEB / "roslibpy_client.py"), graph.ws], graph.env())
    try:
        out = proc.read_until("RESULT ", timeout=60)
    finally:
        out += proc.stop()
    lines = [line for line in out.splitlines() if line.startswith("RESULT ")]
    assert lines, out
    result = json.loads(lines[0][len("RESULT "):])
    assert result["connected"] is True
    assert "/turtle1/pose" in result["topics"] and "/chatter" in result["topics"]
    assert result["topic_type"] == "turtlesim/Pose"
    assert "/turtlesim" in result["nodes"] and "/minros_web" in result["nodes"]
    assert "/spawn" in result["services"] and "/rosapi/topics" in result["services"]
    assert result["service_type"] == "turtlesim/Spawn"
    twist = result["message_details"]["typedefs"][0]
    assert twist["type"] == "geometry_msgs/Twist" and twist["fieldnames"] == ["linear", "angular"]
    assert result["message_details"]["typedefs"][1]["fieldtypes"] == ["float64"] * 3
    assert result["request_details"]["typedefs"][0]["fieldnames"] == ["x", "y", "theta", "name"]
    # the turtle drove along +x: roslibpy's cmd_vel reached turtlesim, its pose came back
    first, last = result["first_pose"], result["last_pose"]
    assert first is not None and abs(first["x"] - 5.544445) < 1e-3
    assert last["x"] > first["x"] + 1.0 and abs(last["y"] - first["y"]) < 1e-3
    assert result["spawn"] == {"name": "webturtle"}
    assert "turtlesim/SpawnRequest message requires a float32 for field x" in result["bad_call"]
    assert result["param"] == {"kp": 1.5, "names": ["a", "b"]}
    assert "/web_test/gains/kp" in result["param_names"]
    assert result["advertised_call"] == {"sum": 42}
    assert result["time"]["secs"] > 1_600_000_000


# -- Foxglove --------------------------------------------------------------------------------

def test_foxglove_client_receives_and_decodes_a_topic(graph):
    lines = node_client("echo", graph.ws, "/turtle1/pose", "3")
    info = lines[0]["serverInfo"]
    assert info["supportedEncodings"] == ["ros1"]
    assert {"clientPublish", "parameters", "parametersSubscribe", "services",
            "connectionGraph"} <= set(info["capabilities"])
    channel = lines[1]["channel"]
    assert channel["encoding"] == "ros1" and channel["schemaEncoding"] == "ros1msg"
    assert channel["schemaName"] == "turtlesim/Pose"
    assert channel["schema"].startswith("float32 x\nfloat32 y\nfloat32 theta")
    messages = [line for line in lines if "message" in line]
    assert len(messages) == 3
    assert set(messages[0]["message"]) == {"x", "y", "theta", "linear_velocity", "angular_velocity"}
    assert all(m["size"] == 20 for m in messages)  # 5 float32: the TCPROS body, forwarded as is


def test_foxglove_client_publishes_calls_services_and_sets_parameters(graph):
    lines = node_client("call", graph.ws, "/turtle1/teleport_absolute",
                        '{"x": 3.0, "y": 4.0, "theta": 0.0}')
    assert lines[-1] == {"response": {}, "callId": 7}
    pose = node_client("echo", graph.ws, "/turtle1/pose", "1")[-1]["message"]
    assert abs(pose["x"] - 3.0) < 1e-3 and abs(pose["y"] - 4.0) < 1e-3

    lines = node_client("call", graph.ws, "/rosapi/topic_type", '{"topic": "/chatter"}')
    assert lines[-1]["response"] == {"type": "std_msgs/String"}

    node_client("publish", graph.ws, "/turtle1/cmd_vel",
                '{"linear": {"x": 0, "y": 0, "z": 0}, "angular": {"x": 0, "y": 0, "z": 1.0}}', "5")
    pose = node_client("echo", graph.ws, "/turtle1/pose", "1")[-1]["message"]
    assert pose["theta"] > 0.2  # turned left

    lines = node_client("params", graph.ws, "/fox/gain", "2.5")
    got = [line["parameterValues"] for line in lines if "parameterValues" in line]
    assert got[-1]["id"] == "get-1"
    assert got[-1]["parameters"] == [{"name": "/fox/gain", "value": 2.5, "type": "float64"}]

    lines = node_client("graph", graph.ws, "/turtlesim")
    update = lines[-1]["graph"]
    published = {t["name"]: t["publisherIds"] for t in update["publishedTopics"]}
    assert published["/turtle1/pose"] == ["/turtlesim"]
    services = {s["name"] for s in update["advertisedServices"]}
    assert "/spawn" in services


# -- roslib in Chromium ----------------------------------------------------------------------

def test_roslib_in_headless_chromium(graph):
    playwright = pytest.importorskip("playwright.sync_api")
    need(Path(CHROMIUM).exists(), "Debian's chromium is needed for the browser test")
    need((JS / "node_modules" / "roslib").is_dir(), "tests/web/js/node_modules (npm ci) is needed")
    # The page comes from a loopback HTTP server (Chromium's local network access checks keep
    # pages of other origins from opening ws://127.0.0.1).
    import functools
    import http.server

    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(WEB))
    handler.func.extensions_map = {**handler.func.extensions_map, ".js": "text/javascript",
                                   ".mjs": "text/javascript"}
    handler.func.log_message = lambda *args: None
    pages = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=pages.serve_forever, name="test-pages", daemon=True).start()
    base = f"http://127.0.0.1:{pages.server_address[1]}/"
    with playwright.sync_playwright() as p:
        browser = launch_chromium(p)
        try:
            page = browser.new_page()
            console: list = []
            page.on("console", lambda m: console.append(m.text))
            page.on("pageerror", lambda e: console.append(str(e)))
            page.goto(f"{base}roslib_page.html?ws={graph.ws}")
            try:
                page.wait_for_function("window.results && window.results.messages.length >= 3 && "
                                       "window.results.cbor.length >= 1 && "
                                       "window.results.param === 42 && window.results.topics",
                                       timeout=20_000)
            except playwright.Error as exc:
                state = page.evaluate("window.results")
                raise AssertionError(f"{exc}\nresults: {state}\nconsole: {console}") from None
            results = page.evaluate("window.results")
        finally:
            browser.close()
            pages.shutdown()
            pages.server_close()
    assert results["connected"] is True and results["errors"] == []
    assert results["messages"][0] == {"data": "hello web"}
    assert results["cbor"][0] == {"data": "hello web"}
    assert "/chatter" in results["topics"]["topics"]
    idx = results["topics"]["topics"].index("/chatter")
    assert results["topics"]["types"][idx] == "std_msgs/String"


# -- video -----------------------------------------------------------------------------------

def read_mjpeg_parts(url: str, count: int, timeout: float = 20) -> tuple:
    """The first ``count`` JPEG parts of an MJPEG stream, and the response headers."""
    with urllib.request.urlopen(url, timeout=timeout) as response:
        headers = {k.lower(): v for k, v in response.headers.items()}
        data = b""
        parts: list = []
        deadline = time.monotonic() + timeout
        while len(parts) < count and time.monotonic() < deadline:
            data += response.read1(65536)
            while True:
                start = data.find(b"Content-Length: ")
                if start < 0:
                    break
                end = data.find(b"\r\n\r\n", start)
                if end < 0:
                    break
                length = int(data[start + 16:data.find(b"\r\n", start)])
                if len(data) < end + 4 + length:
                    break
                parts.append(data[end + 4:end + 4 + length])
                data = data[end + 4 + length:]
    return parts, headers


#: a minros camera: 1920x1080 bgr8 at 15 Hz, the top half white and the bottom half black
CAMERA_1080P = r"""
import rospy
from sensor_msgs.msg import Image

rospy.init_node("camera_1080p")
pub = rospy.Publisher("/camera_1080p/image_raw", Image, queue_size=2)
half = 540 * 1920 * 3
img = Image(height=1080, width=1920, encoding="bgr8", step=1920 * 3,
            data=b"\xff" * half + b"\x00" * half)
rate = rospy.Rate(15)
while not rospy.is_shutdown():
    img.header.stamp = rospy.Time.now()
    pub.publish(img)
    rate.sleep()
"""


def test_the_image_view_gets_1080p_over_shared_memory_from_a_minros_camera(graph, tmp_path):
    """Issue 36: minros web's tap connects through the node's protocols, so a minros camera on
    this host reaches the page's image view (/stream, what images.js opens) over MINROSSHM, at
    full size (the old receiver offered TCPROS only)."""
    from minros.transport import shm
    from minros.wire.slaveapi import SlaveClient

    need(shm.supported(), "no shared memory on this system")
    script = tmp_path / "camera_1080p.py"
    script.write_text(CAMERA_1080P)
    camera = Proc([PYTHON, str(script)], graph.env())
    url = f"{graph.http}/stream?topic=/camera_1080p/image_raw"
    try:
        parts, _ = read_mjpeg_parts(url, 3, timeout=30)
        assert len(parts) == 3
        frame = cv2.imdecode(np.frombuffer(parts[-1], np.uint8), cv2.IMREAD_COLOR)
        assert frame.shape == (1080, 1920, 3)
        assert frame[:500].mean() > 240 and frame[580:].mean() < 15
        # the tap lives while a viewer does: ask which transport it took with one open
        with urllib.request.urlopen(url, timeout=30) as viewer:
            seen = b""
            while seen.count(b"Content-Length: ") < 2:  # a frame came through this viewer's tap
                chunk = viewer.read1(65536)
                assert chunk, "the stream ended"
                seen += chunk
            master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{graph.port}/")
            uri = master.lookupNode("/test", "/minros_web")[2]
            with SlaveClient(uri, "/test", timeout=10) as web:
                rows = [row for row in web.get_bus_info()
                        if row[4] == "/camera_1080p/image_raw" and row[2] == "i"]
        assert rows and {row[3] for row in rows} == {"MINROSSHM"}, rows
    finally:
        camera.stop()


def test_seed_video_subscriber_frames_appear_at_stream(graph, tmp_path):
    """video_sub.py, unmodified, with opencv-python-headless: its 'camera' window is streamed."""
    fake = tmp_path / "fakecam"
    fake.mkdir()
    pub = Proc([PYTHON, str(VIDEO / "video_pub.py")],
               graph.env({"PYTHONPATH": str(FAKECAM), "FAKECAM_DIR": str(fake)}))
    sub = Proc([PYTHON, str(VIDEO / "video_sub.py")], graph.env())
    try:
        notice = sub.read_until("[imshow]", timeout=30)
        assert "/stream_viewer?topic=/imshow/camera" in notice
        parts, headers = read_mjpeg_parts(f"{graph.http}/stream?topic=/imshow/camera", 3)
        assert headers["content-type"].startswith("multipart/x-mixed-replace;boundary=")
        assert "access-control-allow-origin" not in headers  # was *: any site could read them
        assert len(parts) == 3
        frame = cv2.imdecode(np.frombuffer(parts[-1], np.uint8), cv2.IMREAD_COLOR)
        assert frame.shape == (480, 640, 3)
        # the publisher's blue 'A' at (150, 150) survived the trip (JPEG: roughly blue)
        glyph = frame[125:155, 148:178].reshape(-1, 3).astype(int)
        assert ((glyph[:, 0] > 180) & (glyph[:, 1] < 80) & (glyph[:, 2] < 80)).sum() > 15
        with urllib.request.urlopen(f"{graph.http}/snapshot?topic=/imshow/camera", timeout=20) as r:
            assert r.headers["Content-Type"] == "image/jpeg"
            assert cv2.imdecode(np.frombuffer(r.read(), np.uint8), cv2.IMREAD_COLOR).shape == (480, 640, 3)
        # a viewer's size is capped (was ~900 MB for one snapshot at 16384 x 16384)
        huge = f"{graph.http}/snapshot?topic=/imshow/camera&width=16384&height=16384"
        with urllib.request.urlopen(huge, timeout=30) as r:
            shape = cv2.imdecode(np.frombuffer(r.read(), np.uint8), cv2.IMREAD_COLOR).shape
        assert shape == (2880, 2880, 3)
        small, _ = read_mjpeg_parts(f"{graph.http}/stream?topic=/video_frames&width=320&height=240&quality=50", 1)
        assert cv2.imdecode(np.frombuffer(small[0], np.uint8), cv2.IMREAD_COLOR).shape == (240, 320, 3)
        with urllib.request.urlopen(f"{graph.http}/stream_viewer?topic=/imshow/camera", timeout=10) as r:
            assert b'<img src="/stream?topic=/imshow/camera">' in r.read()
        with urllib.request.urlopen(f"{graph.http}/streams", timeout=10) as r:
            listing = r.read().decode()
        assert "/imshow/camera" in listing and "/video_frames" in listing
    finally:
        pub_out = pub.stop()
        sub_out = sub.stop()
    assert "Traceback" not in pub_out + sub_out
    assert "not implemented" not in sub_out


def test_video_endpoints_report_bad_requests(graph):
    def status(path: str) -> tuple:
        try:
            with urllib.request.urlopen(graph.http + path, timeout=10) as r:
                return r.status, r.read().decode()
        except urllib.error.HTTPError as exc:
            return exc.code, exc.read().decode()

    code, text = status("/stream")
    assert code == 400 and "missing ?topic=" in text
    code, text = status("/snapshot?topic=/chatter")
    assert code == 415 and "std_msgs/String, not a sensor_msgs/Image" in text
    code, text = status("/stream?topic=/x&width=abc")
    assert code == 400 and "width='abc' is not an integer" in text
    code, text = status("/no/such/page")
    assert code == 404
    code, text = status("/%00")  # was a 500 (ValueError: embedded null byte)
    assert code == 400 and "control character" in text
    code, text = status("/" + "a" * 5000)
    assert code == 404 and "Traceback" not in text
    code, text = status("/")
    assert code == 200 and "minros web" in text


# -- pages of other sites ---------------------------------------------------------------------

def refusal(url: str, **kwargs) -> tuple:
    """(status, body) of a WebSocket upgrade the server refuses."""
    from websockets.exceptions import InvalidStatus

    with pytest.raises(InvalidStatus) as refused:
        raw_client(url, **kwargs).close()
    return refused.value.response.status_code, bytes(refused.value.response.body).decode()


def upgrade_head(port: int, *headers: str) -> bytes:
    """What the server answers a WebSocket upgrade sent with exactly these headers."""
    with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
        sock.sendall(("GET / HTTP/1.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
                      + "".join(h + "\r\n" for h in headers) + "\r\n").encode())
        return sock.recv(65536)


def http_status(url: str, headers: dict) -> tuple:
    request = urllib.request.Request(url, headers=headers)
    try:
        with urllib.request.urlopen(request, timeout=10) as r:
            return r.status, r.read().decode(errors="replace"), dict(r.headers)
    except urllib.error.HTTPError as exc:
        return exc.code, exc.read().decode(), dict(exc.headers)


def test_pages_of_other_sites_and_foreign_host_names_are_refused(graph):
    """A page on any site used to drive the server (rosapi set_param, publish, services), and
    a name of the attacker's resolving to 127.0.0.1 (DNS rebinding) was served."""
    code, body = refusal(graph.ws, origin="http://evil.example")
    assert code == 403 and body.count("\n") == 1
    assert "refused a page of http://evil.example" in body
    assert "--allow-origin http://evil.example" in body
    code, body = refusal(graph.ws, origin="null")  # sandboxed frames: any site makes them
    assert code == 403 and "--allow-origin null" in body
    head = upgrade_head(graph.web_port, f"Host: evil.example:{graph.web_port}")
    assert head.startswith(b"HTTP/1.1 403") and b"refused the host name 'evil.example'" in head
    code, body, _ = http_status(graph.http + "/", {"Host": f"rebind.evil.example:{graph.web_port}"})
    assert code == 403 and f"--allow-origin http://rebind.evil.example:{graph.web_port}" in body
    assert http_status(graph.http + "/", {"Origin": "not an origin"})[0] == 403
    # nothing of the refused clients reached ROS
    assert "evil" not in json.dumps(call_rosapi(graph.ws, "/rosapi/get_param_names"))

    # a script (no Origin), the server's own page, a page on localhost: served
    for kwargs in ({}, {"origin": f"http://127.0.0.1:{graph.web_port}"},
                   {"origin": "http://localhost:3000"}, {"origin": "http://[::1]:8080"}):
        with raw_client(graph.ws, **kwargs) as ws:
            ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "t"}))
            assert json.loads(ws.recv(timeout=10))["result"] is True, kwargs
    for host in (f"localhost:{graph.web_port}", f"127.0.0.1:{graph.web_port}",
                 f"[::1]:{graph.web_port}", f"{socket.gethostname()}:{graph.web_port}"):
        assert http_status(graph.http + "/", {"Host": host})[0] == 200, host
    # the video endpoints no longer tell every site it may read them
    _, _, headers = http_status(graph.http + "/snapshot?topic=/chatter", {})
    assert "Access-Control-Allow-Origin" not in headers
    _, _, headers = http_status(graph.http + "/snapshot?topic=/chatter",
                                {"Origin": "http://localhost:3000"})
    assert headers.get("Access-Control-Allow-Origin") == "http://localhost:3000"


def call_rosapi(url: str, service: str, **args) -> dict:
    with raw_client(url) as ws:
        ws.send(json.dumps({"op": "call_service", "service": service, "args": args, "id": "r"}))
        reply = json.loads(ws.recv(timeout=10))
    assert reply["result"] is True, reply
    return reply["values"]


def test_allow_origin_lets_a_foxglove_app_hosted_elsewhere_in(graph):
    """Foxglove's and Lichtblick's web apps are pages of their own sites: --allow-origin (and
    MINROS_WEB_ALLOW_ORIGIN) let them in, and only them."""
    web, port = start_web(graph.port, graph.home, "--allow-origin", "https://app.foxglove.dev",
                          "__name:=web_allow_origin",
                          env={"MINROS_WEB_ALLOW_ORIGIN": "https://lichtblick.example:8443, null"})
    url = f"ws://127.0.0.1:{port}"
    try:
        for origin in ("https://app.foxglove.dev", "https://lichtblick.example:8443"):
            lines = node_client("echo", url, "/turtle1/pose", "1",
                                env={"FOXGLOVE_CLIENT_ORIGIN": origin})
            assert lines[0]["serverInfo"]["supportedEncodings"] == ["ros1"], origin
            assert "x" in lines[-1]["message"], origin
        done = node_client("echo", url, "/turtle1/pose", "1", check=False,
                           env={"FOXGLOVE_CLIENT_ORIGIN": "https://app.foxglove.dev.evil.example"})
        assert done[-1]["error"] == "Unexpected server response: 403"
        with raw_client(url, origin="null") as ws:  # allowed by name
            ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "t"}))
            assert json.loads(ws.recv(timeout=10))["result"] is True
        code, _, headers = http_status(f"http://127.0.0.1:{port}/snapshot?topic=/chatter",
                                       {"Origin": "https://app.foxglove.dev"})
        assert headers.get("Access-Control-Allow-Origin") == "https://app.foxglove.dev"
    finally:
        out = web.stop()
    assert "refused a page of https://app.foxglove.dev.evil.example" in out
    assert "Traceback" not in out


def test_a_malformed_allow_origin_is_one_line(graph):
    done = subprocess.run([PYTHON, "-m", "minros", "web", "--port", str(free_port()),
                           "--allow-origin", "app.foxglove.dev/path"], env=graph.env(),
                          capture_output=True, text=True, timeout=30)
    assert done.returncode == 2
    assert done.stderr.strip() == ("minros web: error: --allow-origin 'app.foxglove.dev/path' "
                                   "is not an origin: give scheme://host[:port] (no path), e.g. "
                                   "https://app.foxglove.dev, or * for any")


# -- bad input ------------------------------------------------------------------------------

def raw_client(url: str, **kwargs):
    from websockets.sync.client import connect

    return connect(url, open_timeout=10, **kwargs)


def next_status(ws) -> dict:
    while True:
        msg = json.loads(ws.recv(timeout=10))
        if msg.get("op") == "status":
            return msg


@pytest.mark.smoke
def test_bad_input_gets_status_and_leaves_others_alone(graph):
    with raw_client(graph.ws) as bystander, raw_client(graph.ws) as ws:
        bystander.send(json.dumps({"op": "subscribe", "topic": "/chatter", "id": "keep"}))
        assert json.loads(bystander.recv(timeout=10))["msg"] == {"data": "hello web"}

        ws.send("{not json")
        assert "not valid JSON" in next_status(ws)["msg"]
        ws.send(json.dumps({"op": "dance", "id": "d1"}))
        status = next_status(ws)
        assert status["level"] == "error" and status["id"] == "d1"
        assert status["msg"].startswith("Unknown operation: dance.  Allowed operations: [")
        ws.send(json.dumps({"op": "subscribe", "topic": "/nothing_here", "type": "no_pkg/Nope"}))
        assert "Unable to load the message type no_pkg/Nope" in next_status(ws)["msg"]
        ws.send(json.dumps({"op": "subscribe", "topic": "/never_advertised"}))
        assert next_status(ws)["msg"] == ("subscribe: Cannot infer topic type for topic "
                                          "/never_advertised as it is not yet advertised")
        ws.send(json.dumps({"op": "publish", "topic": "/turtle1/cmd_vel",
                            "msg": {"linear": {"q": 1}}}))
        assert next_status(ws)["msg"] == ("publish: Message type geometry_msgs/Twist does not "
                                          "have a field linear.q")
        ws.send(json.dumps({"op": "publish", "topic": "/turtle1/cmd_vel",
                            "msg": {"linear": {"x": "fast"}}}))
        assert next_status(ws)["msg"] == ("publish: geometry_msgs/Twist message requires a "
                                          "float64 for field linear.x, but got a <class 'str'>")
        ws.send(json.dumps({"op": "subscribe", "topic": "/chatter", "type": "std_msgs/Int32"}))
        assert "already established with type std_msgs/String" in next_status(ws)["msg"]
        # the bad client still works, and so does the bystander
        ws.send(json.dumps({"op": "call_service", "service": "/rosapi/topic_type",
                            "args": {"topic": "/chatter"}, "id": "c1"}))
        reply = json.loads(ws.recv(timeout=10))
        assert reply == {"op": "service_response", "service": "/rosapi/topic_type",
                         "values": {"type": "std_msgs/String"}, "result": True, "id": "c1"}
        assert json.loads(bystander.recv(timeout=10))["op"] == "publish"


def test_oversize_frame_closes_only_that_client(tmp_path, minros_core, ros_home):
    from websockets.exceptions import ConnectionClosed

    web, port = start_web(minros_core, ros_home, "--max-message-size", "1000")
    out = ""
    try:
        with raw_client(f"ws://127.0.0.1:{port}") as other, raw_client(f"ws://127.0.0.1:{port}") as ws:
            ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "t"}))
            assert json.loads(ws.recv(timeout=10))["result"] is True  # its handler is running
            ws.send(json.dumps({"op": "publish", "topic": "/x", "msg": {"data": "y" * 5000}}))
            with pytest.raises(ConnectionClosed) as closed:
                ws.recv(timeout=10)
            assert closed.value.sent is not None and closed.value.sent.code == 1009
            other.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "t"}))
            assert json.loads(other.recv(timeout=10))["result"] is True
        out = web.read_until("sent a message larger than 1000 bytes", timeout=15)
    finally:
        out += web.stop()
    assert "Traceback" not in out


def test_token_is_required(minros_core, ros_home):
    from websockets.exceptions import InvalidStatus

    web, port = start_web(minros_core, ros_home, "--token", "s3cret")
    try:
        with pytest.raises(InvalidStatus) as refused:
            raw_client(f"ws://127.0.0.1:{port}/?token=wrong")
        assert refused.value.response.status_code == 401
        assert b"wrong or missing token" in refused.value.response.body
        with pytest.raises(urllib.error.HTTPError) as http_refused:
            urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=10)
        assert http_refused.value.code == 401
        with raw_client(f"ws://127.0.0.1:{port}/?token=s3cret") as ws:
            ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "t"}))
            assert json.loads(ws.recv(timeout=10))["result"] is True
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/?token=s3cret", timeout=10) as r:
            assert r.status == 200
    finally:
        out = web.stop()
    assert "wrong or missing token" in out


def test_client_that_never_reads_is_closed_and_others_keep_receiving(minros_core, ros_home):
    """A rosbridge client subscribes to a 1 MB/s stream and stops reading: the server keeps
    only its latest messages, closes it after --send-timeout, and another client is served."""
    env = ros_env(minros_core, ros_home)
    pub = Proc([PYTHON, "-m", "minros", "topic", "pub", "-r", "50", "/blob", "std_msgs/String",
                "data: '" + "z" * 20000 + "'"], env)
    web, port = start_web(minros_core, ros_home, "--send-timeout", "2")
    try:
        stalled = socket.create_connection(("127.0.0.1", port))
        stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        stalled.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                        b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n")
        assert b"101 Switching Protocols" in stalled.recv(4096)
        frame = json.dumps({"op": "subscribe", "topic": "/blob", "type": "std_msgs/String"}).encode()
        stalled.sendall(bytes([0x81, 0x80 | len(frame)]) + b"\0\0\0\0" + frame)  # masked, key 0
        received = []
        with raw_client(f"ws://127.0.0.1:{port}") as ws:
            ws.send(json.dumps({"op": "subscribe", "topic": "/blob", "type": "std_msgs/String"}))
            deadline = time.monotonic() + 8
            while time.monotonic() < deadline:
                received.append(json.loads(ws.recv(timeout=5)))
            assert len(received) > 100  # ~50 Hz for 8 s while the stalled client is there
        out = web.read_until("has not read anything", timeout=10)
        assert "closing client" in out
        stalled.close()
    finally:
        out = web.stop()
        pub.stop()
    assert "Traceback" not in out


def test_idle_sessions_of_one_peer_do_not_lock_others_out(minros_core, ros_home):
    """512 idle WebSocket sessions from one address used to fill the server for good (503 on
    / and on every upgrade): sessions count as idle now, so the idlest make room, and one
    address keeps at most its share."""
    web, port = start_web(minros_core, ros_home)
    idle = []
    try:
        for _ in range(512):
            sock = socket.create_connection(("127.0.0.1", port), timeout=10)
            idle.append(sock)
            sock.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n"
                         b"Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                         b"Sec-WebSocket-Version: 13\r\n\r\n")
            assert sock.recv(4096).startswith(b"HTTP/1.1 101")
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=10) as r:
            assert r.status == 200
        with raw_client(f"ws://127.0.0.1:{port}") as ws:
            ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "t"}))
            assert json.loads(ws.recv(timeout=10))["result"] is True
        roslibpy = subprocess.run([PYTHON, str(WEB / "roslibpy_client.py"),
                                   f"ws://127.0.0.1:{port}", "connect"], capture_output=True,
                                  text=True, timeout=60, env=ros_env(minros_core, ros_home))
        result = json.loads(roslibpy.stdout.split("RESULT ", 1)[1])
        assert result["connected"] is True and result["time"]["secs"] > 0
        closed = 0
        for sock in idle:  # the oldest were closed to make room: 384 (3/4) at most are left
            sock.setblocking(False)
            try:
                closed += sock.recv(1 << 16) == b""
            except BlockingIOError:
                pass
            except OSError:
                closed += 1
        assert closed >= 512 - WEB_PEER_SHARE
        out = web.read_until("the idlest, to make room", timeout=10)
    finally:
        for sock in idle:
            sock.close()
        out = web.stop()
    assert "Traceback" not in out


#: the connections one address may hold (3/4 of minros web's 512)
WEB_PEER_SHARE = 384


def test_a_service_response_with_result_false_answers_as_rosbridge_does(graph):
    """rosbridge_suite's ROS 1 server hands the client's values to the ROS caller whatever
    `result` says; minros answered 'client went away'. Values that do not fit fail the call
    at once (rosbridge leaves the caller waiting for good)."""
    done = subprocess.run([PYTHON, str(WEB / "roslibpy_client.py"), graph.ws, "refusing_service"],
                          capture_output=True, text=True, timeout=60, env=graph.env())
    result = json.loads(done.stdout.split("RESULT ", 1)[1])
    assert result == {"response": {"sum": 42}}, done.stderr[-2000:]

    with raw_client(graph.ws) as server:
        server.send(json.dumps({"op": "advertise_service", "service": "/web_bad_answer",
                                "type": "rospy_tutorials/AddTwoInts"}))
        caller = Proc([PYTHON, "-m", "minros", "service", "call", "/web_bad_answer",
                       "{a: 1, b: 2}"], graph.env())
        request = json.loads(server.recv(timeout=20))
        assert request["op"] == "call_service" and request["args"] == {"a": 1, "b": 2}
        started = time.monotonic()
        server.send(json.dumps({"op": "service_response", "service": "/web_bad_answer",
                                "id": request["id"], "values": "no can do", "result": False}))
        status = next_status(server)
        assert "Expected field values to be one of" in status["msg"]
        out = caller.read_until("does not fit", timeout=20)
        assert time.monotonic() - started < 10
        assert "went away" not in out
        caller.stop()


MANY_TOPICS_PUBLISHER = """
import sys, time, minros
from std_msgs.msg import String
minros.init_node("many_topics", anonymous=True)
pubs = [minros.Publisher(f"/many/t{i}", String, queue_size=2) for i in range(int(sys.argv[1]))]
print("ready", flush=True)
while not minros.is_shutdown():
    for i, pub in enumerate(pubs):
        pub.publish(String(f"{sys.argv[2]}:t{i}"))
    time.sleep(0.2)
"""


def server_threads(pid: int) -> int:
    with open(f"/proc/{pid}/status") as f:
        return int(next(line for line in f if line.startswith("Threads:")).split()[1])


def test_many_subscriptions_take_no_thread_each(minros_core, ros_home):
    """A client subscribed to 2,000 topics drove the server to 2,017 threads (one per
    publisher connection): the web node's subscriptions share one receive thread now. The
    publisher restarting (a new URI) and dropping its connections are picked up again."""
    env = ros_env(minros_core, ros_home)
    count = 120
    web, port = start_web(minros_core, ros_home)
    pub = Proc([PYTHON, "-c", MANY_TOPICS_PUBLISHER, str(count), "first"], env)
    topics = [f"/many/t{i}" for i in range(count)]

    def all_deliver(ws, marker: str) -> None:
        seen: set = set()
        deadline = time.monotonic() + 60
        while len(seen) < count and time.monotonic() < deadline:
            msg = json.loads(ws.recv(timeout=10))
            name = msg.get("topic", "").rsplit("/", 1)[-1]
            if msg.get("op") == "publish" and msg["msg"] == {"data": f"{marker}:{name}"}:
                seen.add(msg["topic"])
        assert len(seen) == count, f"{len(seen)} of {count} topics delivered"

    try:
        pub.read_until("ready", timeout=30)
        with raw_client(f"ws://127.0.0.1:{port}", max_size=None) as ws:
            for topic in topics:
                ws.send(json.dumps({"op": "subscribe", "topic": topic, "type": "std_msgs/String"}))
            all_deliver(ws, "first")
            threads = server_threads(web.pid)
            assert threads < 40, threads  # was one a publisher connection: count + 17
            info = subprocess.run([PYTHON, "-m", "minros", "node", "info", "/minros_web"],
                                  env=env, capture_output=True, text=True, timeout=30).stdout
            assert "/many/t7 [std_msgs/String]" in info and info.count("* transport: ") >= count
            pub.stop()
            pub = Proc([PYTHON, "-c", MANY_TOPICS_PUBLISHER, str(count), "second"], env)
            pub.read_until("ready", timeout=30)
            all_deliver(ws, "second")
            assert server_threads(web.pid) < 40
    finally:
        pub.stop()
        out = web.stop()
    assert "Traceback" not in out


def test_foxglove_gets_sim_time_from_the_clock_the_node_itself_follows(minros_core, ros_home):
    """On simulated time the web node subscribes to /clock itself (as every node), and the
    Foxglove session's tap shares that Subscriber: it got Clock messages, not bytes, and
    failed on each ('bad callback'), sending no time."""
    env = ros_env(minros_core, ros_home)
    subprocess.run([PYTHON, "-m", "minros", "param", "set", "/use_sim_time", "true"], env=env,
                   check=True, timeout=30)
    clock = Proc([PYTHON, "-c", "import time, minros\n"
                  "from rosgraph_msgs.msg import Clock\n"
                  "minros.init_node('fake_clock')\n"
                  "pub = minros.Publisher('/clock', Clock, queue_size=1)\n"
                  "t = 1000\n"
                  "while not minros.is_shutdown():\n"
                  "    t += 1; pub.publish(Clock(clock=minros.Time(t, 5))); time.sleep(0.05)\n"],
                 env)
    web, port = start_web(minros_core, ros_home)
    try:
        with raw_client(f"ws://127.0.0.1:{port}", subprotocols=["foxglove.websocket.v1"]) as ws:
            info = json.loads(ws.recv(timeout=10))
            assert "time" in info["capabilities"]
            deadline = time.monotonic() + 20
            stamps = []
            while len(stamps) < 3 and time.monotonic() < deadline:
                frame = ws.recv(timeout=10)
                if isinstance(frame, bytes) and frame[0] == 0x02:
                    stamps.append(int.from_bytes(frame[1:9], "little"))
            assert len(stamps) == 3 and all(s % 1_000_000_000 == 5 for s in stamps)
            assert stamps[0] // 1_000_000_000 > 1000
    finally:
        clock.stop()
        out = web.stop()
    assert "bad callback" not in out and "Traceback" not in out


# -- launch files ---------------------------------------------------------------------------

@pytest.mark.parametrize("package, launch_file, needle", [
    ("rosbridge_server", "rosbridge_websocket.launch", "rosbridge_websocket"),
    ("foxglove_bridge", "foxglove_bridge.launch", "foxglove_bridge"),
])
def test_launch_files_start_the_server(minros_core, ros_home, package, launch_file, needle):
    port = free_port()
    launch = Proc([PYTHON, "-m", "minros", "launch", package, launch_file, f"port:={port}",
                   "allow_origin:=https://app.foxglove.dev"], ros_env(minros_core, ros_home))
    try:
        launch.read_until("listening on", timeout=30)
        assert refusal(f"ws://127.0.0.1:{port}", origin="https://evil.example")[0] == 403
        with raw_client(f"ws://127.0.0.1:{port}", origin="https://app.foxglove.dev") as ws:
            ws.send(json.dumps({"op": "call_service", "service": "/rosapi/nodes", "id": "n"}))
            reply = json.loads(ws.recv(timeout=10))
        assert f"/{needle}" in reply["values"]["nodes"]
    finally:
        launch.stop()


def test_rosbridge_websocket_sets_actual_port(minros_core, ros_home):
    """As rosbridge_websocket does: port 0 picks a free port, ~actual_port tells which."""
    launch = Proc([PYTHON, "-m", "minros", "launch", "rosbridge_server",
                   "rosbridge_websocket.launch", "port:=0"], ros_env(minros_core, ros_home))
    try:
        launch.read_until("listening on", timeout=30)
        master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{minros_core}/")
        code, _, port = master.getParam("/test", "/rosbridge_websocket/actual_port")
        assert code == 1 and isinstance(port, int) and port > 0
        with raw_client(f"ws://127.0.0.1:{port}") as ws:
            ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "t"}))
            assert json.loads(ws.recv(timeout=10))["result"] is True
    finally:
        launch.stop()


def test_minros_web_without_master_says_how_to_fix(tmp_path):
    port = free_port()
    done = subprocess.run([PYTHON, "-m", "minros", "web", "--port", str(free_port())],
                          env=ros_env(port, tmp_path), capture_output=True, text=True, timeout=30)
    assert done.returncode == 1
    assert done.stderr.strip().startswith("minros web: error: cannot reach the ROS master at")
    assert "minros core" in done.stderr and "Traceback" not in done.stderr


def test_port_in_use_is_one_line(minros_core, ros_home):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        done = subprocess.run([PYTHON, "-m", "minros", "web", "--port", str(port)],
                              env=ros_env(minros_core, ros_home), capture_output=True, text=True,
                              timeout=30)
    assert done.returncode == 1
    assert f"cannot listen on 127.0.0.1:{port}" in done.stderr and "--port" in done.stderr
    assert "Traceback" not in done.stderr




def test_a_second_minros_web_refuses_the_name_the_first_holds(minros_core, ros_home):
    """It used to take /minros_web and so shut the first server down (ROS's rule for a node
    name), silently. Now it says so in one line, and the first keeps serving; under a name of
    its own it runs beside it, and a name whose holder died (SIGKILL, no unregistration) is
    free again."""
    import signal
    import urllib.request

    first, first_port = start_web(minros_core, ros_home)
    try:
        done = subprocess.run([PYTHON, "-m", "minros", "web", "--port", str(free_port())],
                              env=ros_env(minros_core, ros_home), capture_output=True,
                              text=True, timeout=30)
        assert done.returncode == 1, done.stdout + done.stderr
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in done.stderr
        assert lines[0].startswith("minros web: error: a node named /minros_web is already "
                                   f"running (pid {first.pid}, ")
        assert "minros web --name minros_web2" in lines[0]
        assert first.alive()
        with urllib.request.urlopen(f"http://127.0.0.1:{first_port}/", timeout=10) as page:
            assert page.status == 200
        second, _port = start_web(minros_core, ros_home, "--name", "minros_web2")
        try:
            nodes = subprocess.run([PYTHON, "-m", "minros", "node", "list"],
                                   env=ros_env(minros_core, ros_home), capture_output=True,
                                   text=True, timeout=30).stdout.split()
            assert {"/minros_web", "/minros_web2"} <= set(nodes) and first.alive()
        finally:
            second.stop()
    finally:
        first.popen.send_signal(signal.SIGKILL)
        first.popen.wait(10)
    again, _port = start_web(minros_core, ros_home)
    out = again.stop()
    assert "Traceback" not in out


def test_a_latched_message_reaches_every_client_that_subscribes_later(graph):
    """The web node shares one subscription per topic: a client that subscribes after the
    first still gets the latched message, as from rosbridge_suite."""
    pub = Proc([PYTHON, "-m", "minros", "topic", "pub", "/web_latched", "std_msgs/String",
                "data: kept"], graph.env())
    try:
        pub.read_until("publishing and latching message", timeout=20)
        proc = Proc([PYTHON, str(WEB / "roslibpy_client.py"), graph.ws, "latched_twice"],
                     graph.env())
        try:
            out = proc.read_until("RESULT ", timeout=90)
        finally:
            out += proc.stop()
    finally:
        pub.stop()
    result = json.loads(out.split("RESULT ", 1)[1].splitlines()[0])
    assert result["received"] == [{"data": "kept"}, {"data": "kept"}]
