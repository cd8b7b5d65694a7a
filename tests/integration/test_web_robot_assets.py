"""Robot meshes served by ``minros web``: what Lichtblick's 3D panel does with Foxglove's own
client library (@foxglove/ws-protocol, run by node), and the page's ``/pkg/`` route.

A URDF on /robot_description names meshes by ``package://`` URL in tests/web/scene_pkg; the
Foxglove client reads the parameter as Lichtblick does (getParameters of everything) and
fetches each mesh (``fetchAsset``): the bytes are the files'. Traversal, a file outside every
package, a type off the allow-list, an unknown package and a custom ``~asset_uri_allowlist``
get foxglove_bridge's error status; a token guards /pkg/ like every other piece of data.
"""

from __future__ import annotations

import hashlib
import json
import os
import urllib.error
import urllib.request
import xmlrpc.client
from pathlib import Path

import pytest
from test_web import node_client, start_web

from support import PYTHON, Proc, free_port, ros_env, wait_for_master

WEB = Path(__file__).resolve().parent.parent / "web"
PKG = WEB / "scene_pkg"


class System:
    def __init__(self, tmp: Path) -> None:
        self.home = tmp / "ros_home"
        (self.home / "log").mkdir(parents=True)
        (tmp / "secret.stl").write_bytes(b"solid secret\nendsolid secret\n")
        self.secret = tmp / "secret.stl"
        self.port = free_port()
        self.procs = [Proc([PYTHON, "-m", "minros", "core", "-p", str(self.port)], self.env())]
        try:
            wait_for_master(self.port)
            master = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{self.port}/")
            code, msg, _ = master.setParam("/test", "/robot_description",
                                           (PKG / "urdf" / "robot.urdf").read_text())
            assert code == 1, msg
            self.web, self.web_port = start_web(self.port, self.home, env=self.extra)
            self.procs.append(self.web)
        except BaseException:
            self.stop()  # no fixture stops what never came up
            raise

    @property
    def extra(self) -> dict:
        return {"ROS_PACKAGE_PATH": str(WEB)}

    def env(self) -> dict:
        return ros_env(self.port, self.home, self.extra)

    def stop(self) -> str:
        return "".join(proc.stop() for proc in reversed(self.procs))


@pytest.fixture(scope="module")
def system(tmp_path_factory):
    sys_ = System(tmp_path_factory.mktemp("assets"))
    try:
        yield sys_
    finally:
        out = sys_.stop()
        assert "Traceback" not in out, out[-3000:]


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_a_foxglove_client_fetches_the_robots_meshes_as_lichtblick_does(system):
    refused = ["package://scene_pkg/../scene_pkg/meshes/wedge.stl",
               "package://scene_pkg/meshes/%2e%2e/%2e%2e/scene_pkg/meshes/wedge.stl",
               "package://scene_pkg/package.xml", "file://" + str(system.secret),
               "package://no_such_pkg/meshes/a.stl"]
    lines = node_client("urdf", f"ws://127.0.0.1:{system.web_port}", *refused)
    robot = next(line["robot"] for line in lines if "robot" in line)
    assert robot["meshes"] == ["package://scene_pkg/meshes/pyramid.dae",
                               "package://scene_pkg/meshes/wedge.stl",
                               "package://scene_pkg/meshes/octahedron.obj"]
    assets = {line["asset"]["uri"]: line["asset"] for line in lines if "asset" in line}
    for uri in robot["meshes"]:
        path = PKG / uri[len("package://scene_pkg/"):]
        assert assets[uri]["status"] == 0, assets[uri]
        assert assets[uri]["bytes"] == path.stat().st_size
        assert assets[uri]["sha256"] == sha256(path)
    for uri in refused:
        assert assets[uri]["status"] == 1, assets[uri]
        assert assets[uri]["error"].startswith(f"Failed to retrieve asset {uri}")
    assert "'..' is not allowed" in assets[refused[0]]["error"]
    assert "'..' is not allowed" in assets[refused[1]]["error"]
    assert "not on the asset allow-list" in assets[refused[2]]["error"]
    assert "not inside a ROS package" in assets[refused[3]]["error"]
    assert "package 'no_such_pkg' not found" in assets[refused[4]]["error"]
    # a file:// URL inside the package is served (foxglove_bridge's resource_retriever reads both)
    inside = "file://" + str(PKG / "meshes" / "wedge.stl")
    lines = node_client("urdf", f"ws://127.0.0.1:{system.web_port}", inside)
    asset = next(line["asset"] for line in lines if "asset" in line and line["asset"]["uri"] == inside)
    assert asset["status"] == 0 and asset["sha256"] == sha256(PKG / "meshes" / "wedge.stl")


def get(url: str):
    try:
        with urllib.request.urlopen(url, timeout=10) as response:
            return response.status, response.headers.get("Content-Type"), response.read()
    except urllib.error.HTTPError as exc:
        return exc.code, exc.headers.get("Content-Type"), exc.read()


def test_the_page_route_serves_package_meshes_and_nothing_else(system):
    base = f"http://127.0.0.1:{system.web_port}"
    status, kind, body = get(base + "/pkg/scene_pkg/meshes/wedge.stl")
    assert status == 200 and kind == "model/stl" and body == (PKG / "meshes" / "wedge.stl").read_bytes()
    status, kind, body = get(base + "/pkg/scene_pkg/meshes/pyramid.dae")
    assert status == 200 and kind == "model/vnd.collada+xml" and body.startswith(b"<?xml")
    for path, code, text in [
        ("/pkg/scene_pkg/meshes/%2e%2e/%2e%2e/scene_pkg/meshes/wedge.stl", 403, "'..' is not allowed"),
        ("/pkg/scene_pkg/package.xml", 403, "not on the asset allow-list"),
        ("/pkg/scene_pkg/meshes/missing.stl", 404, "no such file"),
        ("/pkg/nowhere/a.stl", 404, "package 'nowhere' not found"),
    ]:
        status, _kind, body = get(base + path)
        assert status == code, (path, body)
        assert text in body.decode(), body


def test_a_custom_allow_list_and_the_token_guard_the_route(system, tmp_path):
    home = tmp_path / "home"
    (home / "log").mkdir(parents=True)
    web, port = start_web(system.port, home, "--token", "s3cret", "--name", "web_allowlist",
                          "_asset_uri_allowlist:=['^package://scene_pkg/meshes/wedge\\.stl$']",
                          env=system.extra)
    try:
        base = f"http://127.0.0.1:{port}"
        assert get(base + "/pkg/scene_pkg/meshes/wedge.stl")[0] == 401  # no token
        assert get(base + "/pkg/scene_pkg/meshes/wedge.stl?token=s3cret")[0] == 200
        status, _kind, body = get(base + "/pkg/scene_pkg/meshes/pyramid.dae?token=s3cret")
        assert status == 403 and b"allow-list" in body
    finally:
        out = web.stop()
    assert "Traceback" not in out, out


# -- an attacker's downloads hold chunks, not files ------------------------------------------


def rss_mb(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) >> 10
    raise AssertionError(f"no VmRSS for {pid}")


def peak_mb(pid: int, seconds: float, bound: int) -> int:
    """The highest RSS seen in a window of ``seconds`` (a measurement window: nothing to wait
    for), ending early once it crosses ``bound``."""
    import time

    top, end = 0, time.monotonic() + seconds
    while time.monotonic() < end and top <= bound:
        top = max(top, rss_mb(pid))
        time.sleep(0.05)
    return top


def foxglove_fetch(port: int, uri: str, request_id: int, timeout: float = 60) -> bytes:
    """An honest Foxglove client's fetchAsset (the reply's data, status checked)."""
    import json
    import struct

    from websockets.sync.client import connect

    with connect(f"ws://127.0.0.1:{port}", subprotocols=["foxglove.websocket.v1"],
                 max_size=None, open_timeout=10) as ws:
        ws.send(json.dumps({"op": "fetchAsset", "uri": uri, "requestId": request_id}))
        while True:
            msg = ws.recv(timeout=timeout)
            if isinstance(msg, bytes) and msg[0] == 4:
                _op, rid, status, length = struct.unpack_from("<BIBI", msg)
                assert rid == request_id and status == 0, msg[10:10 + length]
                return msg[10 + length:]


def test_unread_downloads_of_a_big_mesh_hold_no_memory(tmp_path):
    """An attacker's script: 30 parallel GETs of a 46 MB mesh that it never reads, then six
    Foxglove clients asking for it eight times each without reading. minros web used to grow
    from 48 MB to 2.8 GB (held after they closed), and by 812 MB for the Foxglove clients.
    Now each connection holds one 64 kB chunk within a 32 MB budget, and honest clients get
    the whole file meanwhile."""
    import contextlib
    import socket

    from websockets.sync.client import connect

    pkg = tmp_path / "pkgs" / "big_pkg"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>big_pkg</name></package>")
    data = os.urandom(46 << 20)
    (pkg / "meshes" / "big.stl").write_bytes(data)
    digest = hashlib.sha256(data).hexdigest()
    del data
    home = tmp_path / "home"
    (home / "log").mkdir(parents=True)
    master_port = free_port()  # a master of its own: the others' private parameters stay there
    procs = [Proc([PYTHON, "-m", "minros", "core", "-p", str(master_port)],
                  ros_env(master_port, home))]
    try:
        wait_for_master(master_port)
        web, port = start_web(master_port, home, env={"ROS_PACKAGE_PATH": str(tmp_path / "pkgs")})
        procs.append(web)
        request = (f"GET /pkg/big_pkg/meshes/big.stl HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n"
                   .encode())
        start = rss_mb(web.pid)
        bound = start + 100
        unread = []
        for _ in range(30):
            sock = socket.create_connection(("127.0.0.1", port), timeout=10)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            sock.sendall(request)
            unread.append(sock)
        peak = peak_mb(web.pid, 4.0, bound)
        assert peak <= bound, f"30 unread downloads took minros web from {start} to {peak} MB"
        status, kind, body = get(f"http://127.0.0.1:{port}/pkg/big_pkg/meshes/big.stl")
        assert status == 200 and kind == "model/stl", body[:300]
        assert hashlib.sha256(body).hexdigest() == digest
        del body
        for sock in unread:
            sock.close()
        with contextlib.ExitStack() as clients:
            for _ in range(6):
                ws = clients.enter_context(connect(
                    f"ws://127.0.0.1:{port}", subprotocols=["foxglove.websocket.v1"],
                    max_size=None, open_timeout=10))
                ws.socket.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
                for request_id in range(8):
                    ws.send(json.dumps({"op": "fetchAsset", "requestId": request_id,
                                        "uri": "package://big_pkg/meshes/big.stl"}))
                clients.callback(ws.socket.close)  # gone without a closing handshake
            peak = peak_mb(web.pid, 4.0, bound)
            assert peak <= bound, (f"six unread Foxglove clients took minros web from {start} "
                                   f"to {peak} MB")
            fetched = foxglove_fetch(port, "package://big_pkg/meshes/big.stl", 99)
            assert hashlib.sha256(fetched).hexdigest() == digest
            del fetched
        after = peak_mb(web.pid, 1.0, bound)
        assert after <= start + 60, f"{after} MB after the clients closed (from {start} MB)"
    finally:
        out = "".join(proc.stop() for proc in reversed(procs))
    assert "Traceback" not in out, out[-3000:]
