"""scripts/install-ros-reference.sh asks apt only for what it may install on this machine.

A fresh machine of this project's image has Node.js 20 from NodeSource, whose nodejs package
bundles npm and conflicts with Debian's npm: asking apt for `nodejs npm` there stopped the
README's test command after 5 seconds. apt-get's simulation of the whole list the script may
install fails on any such conflict, whatever is installed already.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from support import REPO, need

SCRIPT = REPO / "scripts" / "install-ros-reference.sh"
BASH = shutil.which("bash") or "/bin/bash"


@functools.cache
def print_packages(path: str | None = None) -> tuple[str, ...]:
    env = dict(os.environ)
    if path is not None:
        env["PATH"] = path
    out = subprocess.run([BASH, str(SCRIPT), "--print-packages"], env=env, check=True,
                         capture_output=True, text=True, timeout=120)
    return tuple(out.stdout.split())


def apt_machine() -> None:
    need(shutil.which("apt-get") is not None and shutil.which("dpkg-query") is not None,
         "a Debian machine (apt-get, dpkg-query)")


def test_apt_can_install_every_package_the_script_may_request():
    apt_machine()
    packages = print_packages()
    assert "ros-core" in packages and "python3-rospy" in packages
    simulated = subprocess.run(
        ["apt-get", "-s", "install", "--no-install-recommends", *packages],
        capture_output=True, text=True, timeout=600)
    assert simulated.returncode == 0, simulated.stdout[-3000:] + simulated.stderr[-3000:]


def _path_without(tmp_path: Path, *hidden: str) -> str:
    """A PATH with what the script runs, minus the commands named."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("apt-cache", "dpkg-query", "grep", "id"):
        if tool not in hidden:
            os.symlink(shutil.which(tool), bin_dir / tool)
    return str(bin_dir)


def test_node_and_npm_are_asked_of_apt_only_when_the_machine_lacks_them(tmp_path):
    apt_machine()
    have_node = shutil.which("node") is not None
    packages = print_packages()
    assert ("nodejs" in packages) == (not have_node)
    if have_node:
        # whatever ships node (NodeSource here) ships its npm: Debian's would conflict
        assert "npm" not in packages
    bare = print_packages(_path_without(tmp_path))
    assert "nodejs" in bare and "npm" in bare


def test_an_unknown_argument_is_refused():
    out = subprocess.run([BASH, str(SCRIPT), "--frobnicate"], capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 2 and "usage:" in out.stderr


@pytest.mark.parametrize("package", ["python3-pykdl", "python3-interactive-markers"])
def test_the_full_desktop_python_surface_is_part_of_the_reference(package):
    apt_machine()
    assert package in print_packages()


def test_sources_needs_a_folder():
    out = subprocess.run([BASH, str(SCRIPT), "--sources"], capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 2 and "usage:" in out.stderr and "--sources DIR" in out.stderr


def test_sources_fetches_ros_comm_without_touching_the_machines_apt(tmp_path):
    """What scripts/rostest_suites.py runs: Debian's ros-ros-comm source package, fetched
    through a deb-src list of the script's own; the machine's apt lists stay as they were."""
    apt_machine()
    before = {p: p.read_bytes() for p in Path("/etc/apt").rglob("*") if p.is_file()}
    out = subprocess.run([BASH, str(SCRIPT), "--sources", str(tmp_path), "ros-ros-comm"],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stdout + out.stderr
    tree = tmp_path / "ros_comm-1.15.15"
    assert (tree / "test" / "test_rospy" / "test" / "rostest" / "rosout.test").is_file()
    assert (tree / "tools" / "topic_tools" / "test" / "relay_stealth.test").is_file()
    after = {p: p.read_bytes() for p in Path("/etc/apt").rglob("*") if p.is_file()}
    assert after == before
    again = subprocess.run([BASH, str(SCRIPT), "--sources", str(tmp_path)], capture_output=True,
                           text=True, timeout=120)
    assert again.returncode == 0 and "Fetched" not in again.stderr  # nothing fetched again
