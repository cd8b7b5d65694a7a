"""roswtf's command line as ROS's: ``roswtf -h`` is optparse's text (ROS's own test looks for
``Options`` in it), an unknown option exits 2; ``rospack find roswtf`` finds its package."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from support import PYTHON, need, reference_env, ros_env

BIN = Path(PYTHON).parent


def _run(argv: list, home: Path, reference: bool = False) -> subprocess.CompletedProcess:
    env = ros_env(None, home)
    return subprocess.run(argv, env=reference_env(env) if reference else env,
                          capture_output=True, text=True, timeout=60)


def test_help_is_roswtfs(ros_home: Path):
    out = _run([str(BIN / "roswtf"), "-h"], ros_home)
    assert out.returncode == 0
    assert out.stdout.startswith("Usage: roswtf [launch file]\n\n")
    assert "\nOptions:\n  -h, --help    show this help message and exit\n" in out.stdout
    bad = _run([str(BIN / "roswtf"), "--bogus"], ros_home)
    assert bad.returncode == 2
    assert bad.stderr.endswith("roswtf: error: no such option: --bogus\n")


@pytest.mark.interop
def test_help_and_errors_match_debians_roswtf(ros_home: Path):
    need(Path("/usr/bin/roswtf").exists(), "Debian's roswtf", "scripts/install-ros-reference.sh")
    for args in (["-h"], ["--bogus"]):
        mine = _run([str(BIN / "roswtf"), *args], ros_home)
        theirs = _run(["/usr/bin/roswtf", *args], ros_home, reference=True)
        assert (mine.returncode, mine.stdout, mine.stderr) == \
            (theirs.returncode, theirs.stdout, theirs.stderr)


def test_rospack_finds_roswtf(ros_home: Path):
    out = _run([str(BIN / "rospack"), "find", "roswtf"], ros_home)
    assert out.returncode == 0, out.stderr
    folder = Path(out.stdout.strip())
    assert "<name>roswtf</name>" in (folder / "package.xml").read_text()
