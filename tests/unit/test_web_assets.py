"""Which package files minros web serves (the 3D view's /pkg/ and Foxglove's fetchAsset):
foxglove_bridge's allow-list semantics, plus 'inside a package folder' after decoding and
symbolic links."""

from __future__ import annotations

import os
import struct

import pytest

from minros.web import assets
from minros.web import foxglove_protocol as fp


@pytest.fixture
def workspace(tmp_path, monkeypatch):
    """ROS_PACKAGE_PATH with one package, robot_pkg (meshes/base.stl, a secret beside it)."""
    pkg = tmp_path / "ws" / "robot_pkg"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>robot_pkg</name></package>")
    (pkg / "meshes" / "base.stl").write_bytes(b"solid base\nendsolid base\n")
    (pkg / "meshes" / "Wheel.STL").write_bytes(b"solid wheel\nendsolid wheel\n")
    (pkg / "meshes" / "my part.dae").write_bytes(b"<COLLADA/>")
    (tmp_path / "secret.stl").write_bytes(b"not for you")
    os.symlink(tmp_path / "secret.stl", pkg / "meshes" / "link.stl")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))
    return pkg


@pytest.mark.parametrize("uri, ok", [
    ("package://robot_pkg/meshes/base.stl", True),
    ("package://robot_pkg/meshes/Wheel.STL", True),  # CAD exporters write upper case
    ("package://robot_pkg/meshes/my%20part.dae", True),
    ("package://robot_pkg/textures/t.png", True),
    ("file:///opt/robot_pkg/meshes/base.stl", True),
    ("package://robot_pkg/../../etc/passwd.stl", False),  # '..' anywhere
    ("package://robot_pkg/meshes/base.stl.bak", False),
    ("package://robot_pkg/launch/robot.launch", False),
    ("package://robot_pkg/meshes/base.stl\n", False),  # the whole URI must match
    ("http://example.com/base.stl", False),
])
def test_the_default_allow_list_is_foxglove_bridges(uri, ok):
    assert assets.allowed(uri) is ok


def test_a_listed_mesh_is_read_from_its_package(workspace):
    assert assets.read("package://robot_pkg/meshes/base.stl").startswith(b"solid base")
    assert assets.read("package://robot_pkg/meshes/Wheel.STL").startswith(b"solid wheel")
    assert assets.read("package://robot_pkg/meshes/my%20part.dae") == b"<COLLADA/>"
    path = workspace / "meshes" / "base.stl"
    assert assets.read("file://" + str(path)).startswith(b"solid base")


@pytest.mark.parametrize("uri, status, text", [
    ("package://robot_pkg/meshes/%2e%2e/%2e%2e/secret.stl", 403, "'..' is not allowed"),
    ("package://robot_pkg/meshes/link.stl", 403, "not inside a ROS package"),
    ("package://robot_pkg/meshes/missing.stl", 404, "no such file"),
    ("package://no_such_pkg/a.stl", 404, "package 'no_such_pkg' not found"),
    ("package://robot_pkg/package.xml", 403, "not on the asset allow-list"),
])
def test_what_is_refused_says_why(workspace, uri, status, text):
    with pytest.raises(assets.AssetError) as caught:
        assets.read(uri)
    assert caught.value.status == status
    assert text in str(caught.value)


def test_a_file_url_outside_every_package_is_refused(workspace, tmp_path):
    with pytest.raises(assets.AssetError, match="not inside a ROS package"):
        assets.read("file://" + str(tmp_path / "secret.stl"))


def test_a_custom_allow_list_replaces_the_default(workspace):
    patterns = assets.compile_allowlist([r"^package://robot_pkg/meshes/base\.stl$"])
    assert assets.read("package://robot_pkg/meshes/base.stl", patterns)
    with pytest.raises(assets.AssetError, match="allow-list"):
        assets.read("package://robot_pkg/meshes/Wheel.STL", patterns)
    with pytest.raises(ValueError, match="not a regular expression"):
        assets.compile_allowlist(["(unclosed"])


def test_page_urls_of_mesh_uris(workspace):
    assert assets.page_url("package://robot_pkg/meshes/base.stl") == ("/pkg/robot_pkg/meshes/base.stl", None)
    url, problem = assets.page_url("file://" + str(workspace / "meshes" / "my part.dae"))
    assert url == "/pkg/robot_pkg/meshes/my%20part.dae" and problem is None
    url, problem = assets.page_url("package://nowhere/a.stl")
    assert url is None and "package 'nowhere' not found" in problem
    assert assets.page_url("https://example.com/a.dae") == ("https://example.com/a.dae", None)


def test_fetch_asset_response_layout():
    ok = fp.fetch_asset_response(7, b"abc")
    assert ok == struct.pack("<BIBI", 4, 7, 0, 0) + b"abc"
    bad = fp.fetch_asset_response(8, error="Failed to retrieve asset x")
    assert bad == struct.pack("<BIBI", 4, 8, 1, 26) + b"Failed to retrieve asset x"


def test_foxglove_bridge_launch_file_sets_the_allow_list_as_an_argument():
    """roslaunch foxglove_bridge foxglove_bridge.launch: asset_uri_allowlist is an argument, as
    in foxglove_bridge's launch file; by default minros web's own list."""
    from pathlib import Path

    import minros.launch
    from minros.cli.launch import load_all

    launch = (Path(minros.launch.__file__).parent / "share" / "foxglove_bridge" / "launch"
              / "foxglove_bridge.launch")
    params = load_all([str(launch)], []).params
    assert params["/foxglove_bridge/asset_uri_allowlist"] == list(assets.DEFAULT_ALLOWLIST)
    params = load_all([str(launch)], [r"asset_uri_allowlist:=['^package://robot_pkg/.*\.stl$']"]).params
    assert params["/foxglove_bridge/asset_uri_allowlist"] == [r"^package://robot_pkg/.*\.stl$"]


# -- files are streamed: one chunk per connection, a budget across all of them ---------------


def test_the_budget_bounds_bytes_in_memory_and_a_peers_share():
    reports = []
    budget = assets.Budget(total=4 * assets.CHUNK_BYTES, peer_share=0.5, report=reports.append)
    c = assets.CHUNK_BYTES
    assert budget.acquire("10.0.0.1", c, 0) and budget.acquire("10.0.0.1", c, 0)
    # the peer has its share (half of four chunks): it waits, the others do not
    assert not budget.acquire("10.0.0.1", c, 0.05)
    assert len(reports) == 1 and "10.0.0.1 holds its share" in reports[0]
    assert budget.acquire("10.0.0.2", c, 0) and budget.acquire("10.0.0.3", c, 0)
    assert not budget.acquire("10.0.0.4", c, 0.05)  # the whole budget is taken
    assert len(reports) == 1  # one line a minute, not one per wait
    assert budget.used == 4 * c and budget.by_peer == {"10.0.0.1": 2 * c, "10.0.0.2": c,
                                                       "10.0.0.3": c}
    # a waiting reader gets room as soon as one is given back
    import threading

    got = []
    waiter = threading.Thread(target=lambda: got.append(budget.acquire("10.0.0.4", c, 5.0)))
    waiter.start()
    budget.release("10.0.0.2", c)
    waiter.join(5)
    assert got == [True] and "10.0.0.2" not in budget.by_peer


def test_chunks_are_the_file_one_budgeted_chunk_at_a_time(tmp_path):
    data = os.urandom(5 * assets.CHUNK_BYTES + 123)
    (tmp_path / "big.stl").write_bytes(data)
    budget = assets.Budget(total=8 * assets.CHUNK_BYTES)
    stream, size = assets.open_file(tmp_path / "big.stl", "package://p/big.stl")
    out = bytearray()
    held = []
    for chunk in assets.chunks(stream, size, budget, "peer", 1.0):
        held.append(budget.used)
        out += chunk  # the view is reused: copy it before asking for the next
    assert bytes(out) == data and budget.used == 0
    assert max(held) == assets.CHUNK_BYTES and len(held) == 6
    # a consumer that stops half-way gives its chunk back
    stream.seek(0)
    gen = assets.chunks(stream, size, budget, "peer", 1.0)
    next(gen)
    assert budget.used == assets.CHUNK_BYTES
    gen.close()
    assert budget.used == 0
    # no room within the timeout: one clear refusal
    full = assets.Budget(total=assets.CHUNK_BYTES)
    assert full.acquire("other", assets.CHUNK_BYTES, 0)
    with pytest.raises(assets.AssetError, match="no room for package files") as info:
        next(assets.chunks(stream, size, full, "peer", 0.05))
    assert info.value.status == 503
    stream.close()


def test_open_file_refuses_what_is_over_the_limit(tmp_path):
    (tmp_path / "a.stl").write_bytes(b"x" * 100)
    with pytest.raises(assets.AssetError, match="more than the 99 served") as info:
        assets.open_file(tmp_path / "a.stl", "package://p/a.stl", max_bytes=99)
    assert info.value.status == 413
    with pytest.raises(assets.AssetError, match="cannot read") as info:
        assets.open_file(tmp_path / "none.stl", "package://p/none.stl")
    assert info.value.status == 404


def test_a_foxglove_fetch_is_one_message_made_while_it_is_sent(workspace):
    """fetchAsset queues a Fragments item of one chunk's size: the head, then the file's
    chunks, each read when the writer asks for it."""
    import json

    from minros.web.foxglove import FoxgloveSession
    from minros.web.outbox import Outbox

    big = os.urandom(3 * assets.CHUNK_BYTES + 5)
    (workspace / "meshes" / "big.stl").write_bytes(big)
    outbox = Outbox()
    budget = assets.Budget()
    closed = []
    session = FoxgloveSession("127.0.0.1:5000#1", state=None, outbox=outbox,
                              close_client=closed.append, run_async=lambda fn: fn(),
                              asset_budget=budget)
    session.receive(json.dumps({"op": "fetchAsset", "uri": "package://robot_pkg/meshes/big.stl",
                                "requestId": 9}))
    assert outbox._control_bytes == assets.CHUNK_BYTES  # what it holds, not the file's size
    _slot, item = outbox.get(timeout=1)
    assert isinstance(item, assets.Fragments)
    fragments = []
    for fragment in item:
        assert budget.used <= assets.CHUNK_BYTES
        fragments.append(bytes(fragment))
    assert fragments[0] == struct.pack("<BIBI", 4, 9, 0, 0)
    assert b"".join(fragments[1:]) == big and len(fragments) == 5
    assert budget.used == 0 and not closed
    # all eight fetch slots are free again
    assert all(session._fetches.acquire(blocking=False) for _ in range(8))
