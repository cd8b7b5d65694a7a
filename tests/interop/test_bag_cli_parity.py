"""The rosbag file commands and the bag options of rostopic/rosmsg, minros beside Debian's, on
the same files: same output, same exit status (no master needed)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

pytestmark = pytest.mark.interop

MAKE_BAG = r'''
import sys
import rospy
from rosbag import Bag
from std_msgs.msg import String, Int32
from geometry_msgs.msg import PointStamped
with Bag(sys.argv[1], "w", chunk_threshold=4000) as b:
    for i in range(200):
        t = rospy.Time(1000 + i // 20, (i % 20) * 50000000)
        b.write("/words", String("w%d" % i), t)
        if i % 4 == 0:
            p = PointStamped()
            p.header.stamp = t
            p.header.frame_id = "map"
            p.point.x = i / 4.0
            b.write("/points", p, t)
        if i % 50 == 0:
            b.write("/count", Int32(i), t)
'''


def _run(minros: bool, *argv: str, cwd: Path, timeout: float = 60) -> subprocess.CompletedProcess:
    """minros's ``rosTOOL ...`` console script or Debian's (TOOL: bag, topic, msg)."""
    env = dict(os.environ, TZ="UTC")
    if minros:
        cmd = [str(Path(PYTHON).parent / f"ros{argv[0]}"), *argv[1:]]
    else:
        cmd, env = [f"/usr/bin/ros{argv[0]}", *argv[1:]], reference_env(env)
    return subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=timeout)


def both(tmp_path: Path, *argv: str) -> tuple:
    ours = _run(True, *argv, cwd=tmp_path)
    theirs = _run(False, *argv, cwd=tmp_path)
    return ours, theirs


@pytest.fixture
def bagdir(tmp_path: Path) -> Path:
    require_reference()
    script = tmp_path / "make.py"
    script.write_text(MAKE_BAG)
    made = subprocess.run([REFERENCE_PYTHON, str(script), str(tmp_path / "deb.bag")],
                          env=reference_env({}), capture_output=True, text=True, timeout=60)
    assert made.returncode == 0, made.stderr
    made = subprocess.run([PYTHON, str(script), str(tmp_path / "ours.bag")], capture_output=True,
                          text=True, timeout=60)
    assert made.returncode == 0, made.stderr
    return tmp_path


@pytest.mark.parametrize("bag", ["deb.bag", "ours.bag"])
@pytest.mark.parametrize("args", [["info"], ["info", "--freq"], ["info", "-y"],
                                  ["info", "-y", "-k", "topics"], ["info", "-y", "-k", "duration"]])
def test_info_same_output(bagdir, bag, args):
    ours, theirs = both(bagdir, "bag", *args, bag)
    assert (ours.returncode, ours.stdout) == (theirs.returncode, theirs.stdout)


@pytest.mark.parametrize("argv", [
    ["topic", "echo", "-b", "deb.bag", "/points"],
    ["topic", "echo", "-b", "ours.bag", "-n", "3", "/words"],
    ["topic", "echo", "-b", "deb.bag", "/points/point/x"],
    ["topic", "echo", "-b", "ours.bag", "-a", "-n", "5"],
    ["topic", "echo", "-b", "deb.bag", "-p", "/count"],
    ["topic", "list", "-b", "deb.bag"],
    ["topic", "list", "-b", "ours.bag", "/points"],
    ["msg", "show", "-b", "deb.bag", "geometry_msgs/PointStamped"],
    ["msg", "show", "-r", "-b", "ours.bag", "std_msgs/String"],
    ["topic", "echo", "-b", "missing.bag", "/x"],
])
def test_bag_options_of_rostopic_and_rosmsg(bagdir, argv):
    ours, theirs = both(bagdir, *argv)
    assert ours.returncode == theirs.returncode, (ours.stderr, theirs.stderr)
    assert ours.stdout == theirs.stdout
    if theirs.returncode:
        assert ours.stderr.strip().splitlines()[-1] == theirs.stderr.strip().splitlines()[-1]


def _messages(python: str, path: Path) -> list:
    code = ("import sys, rosbag\n"
            "for t, m, s in rosbag.Bag(sys.argv[1]).read_messages():\n"
            "    print(t, s.to_nsec(), repr(m).replace(chr(10), ' '))\n")
    env = reference_env({}) if python == REFERENCE_PYTHON else None
    out = subprocess.run([python, "-c", code, str(path)], env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return out.stdout.splitlines()


def test_filter_like_debian(bagdir):
    expr = "topic == '/points' and m.point.x > 10 or topic == '/count'"
    ours = _run(True, "bag", "filter", "ours.bag", "f-ours.bag", expr, cwd=bagdir)
    theirs = _run(False, "bag", "filter", "deb.bag", "f-deb.bag", expr, cwd=bagdir)
    assert ours.returncode == theirs.returncode == 0, (ours.stderr, theirs.stderr)
    assert "f-ours.bag" in ours.stdout and "100%" in ours.stdout  # rosbag's progress bar
    read_by_debian = _messages(REFERENCE_PYTHON, bagdir / "f-ours.bag")
    assert read_by_debian == _messages(REFERENCE_PYTHON, bagdir / "f-deb.bag")
    assert len(read_by_debian) == 4 + 39
    for argv, status in ((["filter", "nothere.bag", "o.bag", "True"], 2),
                         (["filter", "ours.bag", "ours.bag", "True"], 3),
                         (["filter", "ours.bag"], 2)):
        ours, theirs = both(bagdir, "bag", *argv)
        assert ours.returncode == theirs.returncode == status
        assert ours.stderr.strip().splitlines()[-1] == theirs.stderr.strip().splitlines()[-1]


@pytest.mark.parametrize("flag,name", [(None, "bz2"), ("--lz4", "lz4")])
def test_compress_decompress_like_debian(bagdir, flag, name):
    before = _messages(REFERENCE_PYTHON, bagdir / "deb.bag")
    ours = _run(True, "bag", "compress", *([flag] if flag else []), "deb.bag", cwd=bagdir)
    assert ours.returncode == 0, ours.stderr
    assert (bagdir / "deb.orig.bag").exists()
    info = _run(False, "bag", "info", "-y", "-k", "compression", "deb.bag", cwd=bagdir)
    assert info.stdout.strip() == name
    assert _messages(REFERENCE_PYTHON, bagdir / "deb.bag") == before
    again = both(bagdir, "bag", "compress", "deb.bag")
    assert [r.stderr.strip() for r in again] == ["Skipping deb.bag. Backup path deb.orig.bag already exists."] * 2
    ours = _run(True, "bag", "decompress", "-f", "deb.bag", cwd=bagdir)
    assert ours.returncode == 0, ours.stderr
    info = _run(False, "bag", "info", "-y", "-k", "compression", "deb.bag", cwd=bagdir)
    assert info.stdout.strip() == "none"
    assert _messages(PYTHON, bagdir / "deb.bag") == _messages(REFERENCE_PYTHON, bagdir / "deb.bag") == before


def test_check_and_usage_like_debian(bagdir):
    ours, theirs = both(bagdir, "bag", "check", "deb.bag")
    assert (ours.returncode, ours.stdout) == (theirs.returncode, theirs.stdout)
    assert ours.stdout == "Bag file does not need any migrations.\n"
    for argv in (["bag"], ["bag", "record", "-h"], ["bag", "play", "-h"], ["bag", "info", "-h"],
                 ["bag", "filter", "-h"], ["bag", "reindex", "-h"], ["bag", "compress", "-h"],
                 ["bag", "record"], ["bag", "play"], ["bag", "info"], ["bag", "info", "-k", "x", "a.bag"],
                 ["bag", "record", "-o", "a", "-O", "b", "/x"], ["bag", "record", "--split", "/x"]):
        ours, theirs = both(bagdir, *argv)
        assert (ours.returncode, ours.stdout, ours.stderr) == (theirs.returncode, theirs.stdout, theirs.stderr), argv
