"""catkin workspace tools: package layout, manifests, devel space and its setup files."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from minros.workspace import catkin
from minros.workspace.catkin import WorkspaceError


def _collect():
    lines = []
    return lines, lines.append


def test_create_pkg_layout_and_output_match_catkin(tmp_path: Path):
    lines, out = _collect()
    pkg = catkin.create_package("my_package", ["rospy", "roscpp", "std_msgs"], tmp_path, out=out)
    assert lines == [
        "Created file my_package/package.xml",
        "Created file my_package/CMakeLists.txt",
        "Created folder my_package/include/my_package",
        "Created folder my_package/src",
        f"Successfully created files in {tmp_path / 'my_package'}. Please adjust the values in package.xml.",
    ]
    assert (pkg / "include" / "my_package").is_dir() and (pkg / "src").is_dir()
    root = ET.parse(pkg / "package.xml").getroot()
    assert root.get("format") == "2"
    assert root.findtext("name") == "my_package"
    assert root.findtext("description") == "The my_package package"
    assert [e.text for e in root.findall("buildtool_depend")] == ["catkin"]
    for tag in ("build_depend", "build_export_depend", "exec_depend"):
        assert [e.text for e in root.findall(tag)] == ["roscpp", "rospy", "std_msgs"]
    cmake = (pkg / "CMakeLists.txt").read_text()
    assert "project(my_package)" in cmake
    assert "find_package(catkin REQUIRED COMPONENTS\n  roscpp\n  rospy\n  std_msgs\n)" in cmake


def test_create_pkg_without_roscpp_makes_no_include(tmp_path: Path):
    lines, out = _collect()
    pkg = catkin.create_package("py_only", ["rospy"], tmp_path, out=out)
    assert not (pkg / "include").exists() and (pkg / "src").is_dir()
    bare = catkin.create_package("bare", [], tmp_path, out=out)
    assert not (bare / "src").exists()
    assert "find_package(catkin REQUIRED)" in (bare / "CMakeLists.txt").read_text()


def test_create_pkg_refuses_existing_and_warns_on_convention(tmp_path: Path):
    catkin.create_package("dup", ["rospy"], tmp_path, out=lambda s: None)
    with pytest.raises(WorkspaceError, match="File exists: .*dup/package.xml"):
        catkin.create_package("dup", ["rospy"], tmp_path, out=lambda s: None)
    warnings = []
    catkin.create_package("My-Pkg", [], tmp_path, out=lambda s: None, warn=warnings.append)
    assert warnings and "does not follow the naming conventions" in warnings[0]
    with pytest.raises(WorkspaceError):
        catkin.create_package("../evil", [], tmp_path, out=lambda s: None)


def test_init_workspace_links_toplevel_and_refuses_twice(tmp_path: Path):
    lines, out = _collect()
    target = catkin.init_workspace(tmp_path, out=out)
    assert target.resolve() == catkin.TOPLEVEL_CMAKE
    assert "catkin_workspace()" in target.read_text()
    assert lines[0].startswith(f'Creating symlink "{target}" pointing to ')
    with pytest.raises(WorkspaceError, match="already exists"):
        catkin.init_workspace(tmp_path, out=out)


def test_manifest_depends_and_topological_order(tmp_path: Path):
    src = tmp_path / "src"
    catkin.create_package("zeta", ["rospy"], src, out=lambda s: None)
    catkin.create_package("alpha", ["zeta", "std_msgs"], src / "nested" / "deeper", out=lambda s: None)
    ignored = src / "ignored"
    catkin.create_package("hidden", [], ignored, out=lambda s: None)
    (ignored / "CATKIN_IGNORE").touch()
    found = catkin.find_workspace_packages(src)
    assert sorted(m.name for m in found) == ["alpha", "zeta"]
    assert [m.name for m in catkin.topological_order(found)] == ["zeta", "alpha"]


def test_cyclic_and_duplicate_packages_are_errors(tmp_path: Path):
    src = tmp_path / "src"
    catkin.create_package("a", ["b"], src, out=lambda s: None)
    catkin.create_package("b", ["a"], src, out=lambda s: None)
    with pytest.raises(WorkspaceError, match="circular dependency"):
        catkin.topological_order(catkin.find_workspace_packages(src))
    catkin.create_package("a", [], src / "copy", out=lambda s: None)
    with pytest.raises(WorkspaceError, match='Multiple packages found with the same name "a"'):
        catkin.find_workspace_packages(src)


def test_malformed_manifest_is_one_clear_error(tmp_path: Path):
    pkg = tmp_path / "src" / "broken"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>broken</name>")
    with pytest.raises(WorkspaceError, match="broken/package.xml: cannot read package manifest"):
        catkin.find_workspace_packages(tmp_path / "src")


def test_make_without_src_fails(tmp_path: Path):
    with pytest.raises(WorkspaceError, match='source space ".*/src" does not exist'):
        catkin.make_workspace(tmp_path, out=lambda s: None)
    catkin.init_workspace(tmp_path, out=lambda s: None)  # tmp_path plays a workspace's src/
    with pytest.raises(WorkspaceError, match="must be invoked in the root of workspace"):
        catkin.make_workspace(tmp_path, out=lambda s: None)


def _bash(script: str, cwd: Path, env=None) -> str:
    result = subprocess.run(["bash", "-c", script], cwd=cwd, env=env, capture_output=True,
                            text=True, timeout=30)
    assert result.returncode == 0, result.stderr
    return result.stdout


@pytest.mark.slow
def test_make_writes_devel_space_and_setup_puts_paths_first(tmp_path: Path):
    ws = tmp_path / "ws"
    (ws / "src").mkdir(parents=True)
    pkg = catkin.create_package("my_package", ["rospy"], ws / "src", out=lambda s: None)
    module = pkg / "src" / "my_package"
    module.mkdir(parents=True)
    (module / "__init__.py").write_text("ANSWER = 42\n")
    (module / "helper.py").write_text("def twice(x):\n    return 2 * x\n")
    lines, out = _collect()
    built = catkin.make_workspace(ws, out=out)
    assert [m.name for m in built] == ["my_package"]
    assert lines[0] == f"Base path: {ws}"
    assert "-- +++ processing catkin package: 'my_package'" in lines
    assert (ws / "build").is_dir() and (ws / "src" / "CMakeLists.txt").exists()
    for name in ("setup.bash", "setup.sh", "setup.zsh", "env.sh"):
        assert (ws / "devel" / name).is_file()
    env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "ROS_PACKAGE_PATH": "/elsewhere"}
    printed = _bash(
        "source devel/setup.bash && source devel/setup.bash && "
        'echo "$ROS_PACKAGE_PATH"; echo "$PATH"; echo "$PYTHONPATH"; command -v python; '
        "python -c 'import my_package, my_package.helper as h; print(my_package.ANSWER, h.twice(4))'",
        ws, env).splitlines()
    assert printed[0] == f"{ws / 'src'}:/elsewhere"
    venv_bin = str(Path(sys.executable).absolute().parent)
    assert printed[1] == f"{ws / 'devel' / 'bin'}:{venv_bin}:/usr/bin:/bin"
    assert printed[2] == str(ws / "devel" / "lib" / "python3" / "dist-packages")
    assert printed[3] == os.path.join(venv_bin, "python")
    assert printed[4] == "42 8"


@pytest.mark.slow
def test_env_sh_runs_command_in_workspace(tmp_path: Path):
    ws = tmp_path / "ws"
    (ws / "src").mkdir(parents=True)
    catkin.make_workspace(ws, out=lambda s: None)
    out = subprocess.run([str(ws / "devel" / "env.sh"), "sh", "-c", "echo $ROS_PACKAGE_PATH"],
                         env={"PATH": "/usr/bin:/bin"}, capture_output=True, text=True, timeout=30)
    assert out.stdout.strip() == str(ws / "src")


@pytest.mark.slow
def test_make_generates_importable_messages_and_rejects_malformed(tmp_path: Path):
    ws = tmp_path / "ws"
    (ws / "src").mkdir(parents=True)
    pkg = catkin.create_package("ws_msgs_pkg", ["rospy", "std_msgs"], ws / "src", out=lambda s: None)
    (pkg / "msg").mkdir()
    (pkg / "msg" / "Num.msg").write_text("int64 num\nstring label\n")
    (pkg / "srv").mkdir()
    (pkg / "srv" / "AddTwo.srv").write_text("int64 a\nint64 b\n---\nint64 sum\n")
    lines, out = _collect()
    catkin.make_workspace(ws, out=out)
    assert "-- ws_msgs_pkg: 1 messages, 1 services" in lines
    printed = _bash(
        "source devel/setup.bash && cd / && python -c '"
        "from ws_msgs_pkg.msg import Num; from ws_msgs_pkg.srv import AddTwo, AddTwoRequest; "
        "m = Num(num=7, label=\"x\"); print(m._type, m.num, m.label, AddTwoRequest(1, 2).b)'",
        ws, {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)})
    assert printed.split() == ["ws_msgs_pkg/Num", "7", "x", "2"]
    (pkg / "msg" / "Broken.msg").write_text("int64 num\nnot_a_type@ x\n")
    with pytest.raises(WorkspaceError, match=r"Broken.msg: "):
        catkin.make_workspace(ws, out=lambda s: None)


# A workspace package named as one minros ships comes first and falls back to minros's for
# what it lacks: tests/integration/test_workspace_overlay.py


@pytest.mark.slow
@pytest.mark.parametrize("shell,setup", [("bash", "setup.bash"), ("sh", "setup.sh"), ("zsh", "setup.zsh")])
def test_setup_files_in_each_shell_with_a_space_in_the_path(tmp_path: Path, shell: str, setup: str):
    import shutil

    if shutil.which(shell) is None:
        pytest.skip(f"{shell} is not installed")
    ws = tmp_path / "my ws"
    (ws / "src").mkdir(parents=True)
    catkin.make_workspace(ws, out=lambda s: None)
    script = f'. "{ws}/devel/{setup}"; echo "$ROS_PACKAGE_PATH"; command -v python'
    out = subprocess.run([shell, "-c", script], env={"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)},
                         capture_output=True, text=True, timeout=30)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0] == str(ws / "src")
    assert lines[1] == str(Path(sys.executable).absolute().parent / "python")
