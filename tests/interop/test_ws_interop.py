"""catkin_create_pkg against Debian's catkin_create_pkg (python3-catkin-pkg), the oracle."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from support import reference_env

pytestmark = pytest.mark.interop

BIN = Path(sys.executable).parent
DEBIAN_TOOL = "/usr/bin/catkin_create_pkg"


def _require_tool() -> None:
    if os.path.exists(DEBIAN_TOOL):
        return
    if os.environ.get("CI"):
        pytest.fail(f"{DEBIAN_TOOL} (python3-catkin-pkg) is not installed")
    pytest.skip(f"{DEBIAN_TOOL} is not installed")


def _tree(root: Path):
    return sorted(str(p.relative_to(root)) + ("/" if p.is_dir() else "") for p in root.rglob("*"))


def _elements(package_xml: Path):
    return [(el.tag, (el.text or "").strip(), sorted(el.attrib.items()))
            for el in ET.parse(package_xml).getroot()]


def _code_lines(cmake: Path):
    return [ln for ln in cmake.read_text().splitlines() if ln.strip() and not ln.lstrip().startswith("#")]


@pytest.mark.parametrize("deps", [["rospy", "roscpp", "std_msgs"], ["rospy"], ["std_msgs"], []])
def test_create_pkg_matches_catkin(tmp_path, deps):
    _require_tool()
    ours_dir, theirs_dir = tmp_path / "ours", tmp_path / "theirs"
    ours_dir.mkdir()
    theirs_dir.mkdir()
    env = dict(os.environ)
    ours = subprocess.run([str(BIN / "catkin_create_pkg"), "pkg_x", *deps], cwd=ours_dir, env=env,
                          capture_output=True, text=True, timeout=60)
    theirs = subprocess.run([DEBIAN_TOOL, "pkg_x", *deps], cwd=theirs_dir, env=reference_env(env),
                            capture_output=True, text=True, timeout=60)
    assert ours.returncode == theirs.returncode == 0, theirs.stderr
    assert ours.stdout.replace(str(ours_dir), "DIR") == theirs.stdout.replace(str(theirs_dir), "DIR")
    assert _tree(ours_dir) == _tree(theirs_dir)
    assert _elements(ours_dir / "pkg_x" / "package.xml") == _elements(theirs_dir / "pkg_x" / "package.xml")
    assert _code_lines(ours_dir / "pkg_x" / "CMakeLists.txt") == _code_lines(theirs_dir / "pkg_x" / "CMakeLists.txt")
    # and an existing package is refused by both
    again_ours = subprocess.run([str(BIN / "catkin_create_pkg"), "pkg_x"], cwd=ours_dir, env=env,
                                capture_output=True, text=True, timeout=60)
    again_theirs = subprocess.run([DEBIAN_TOOL, "pkg_x"], cwd=theirs_dir, env=reference_env(env),
                                  capture_output=True, text=True, timeout=60)
    assert again_ours.returncode != 0 and again_theirs.returncode != 0
    last = again_theirs.stderr.strip().splitlines()[-1].replace(str(theirs_dir), "DIR")
    assert again_ours.stderr.strip().replace(str(ours_dir), "DIR") == last
