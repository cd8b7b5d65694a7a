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
