"""genmsg.deps (the message files a .msg/.srv depends on), roslaunch.roslaunch_logs (the log
folder of the running roscore's run) and rosunit.pmon (the launcher's process monitor)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import genmsg
import genmsg.deps
import genmsg.msg_loader
import rosunit.pmon
from minros.launch.rosmodel import RLException


@pytest.fixture
def msg_tree(tmp_path: Path) -> dict:
    std = tmp_path / "std_msgs" / "msg"
    std.mkdir(parents=True)
    (std / "Header.msg").write_text("uint32 seq\ntime stamp\nstring frame_id\n")
    demo = tmp_path / "demo" / "msg"
    demo.mkdir(parents=True)
    (demo / "Point.msg").write_text("float64 x\nfloat64 y\n")
    (demo / "Path.msg").write_text("Header header\nPoint[] points\n")
    srv = tmp_path / "demo" / "srv"
    srv.mkdir()
    (srv / "Plan.srv").write_text("Point goal\n---\nPath path\n")
    (demo / "Missing.msg").write_text("NoSuch thing\n")
    (demo / "Bad.msg").write_text("int32\n")  # a field without a name
    (demo / "Broken.msg").write_text("Bad thing\n")
    return {"std_msgs": [str(std)], "demo": [str(demo)], "root": tmp_path}


def test_msg_dependencies_are_transitive(msg_tree: dict):
    paths = {k: v for k, v in msg_tree.items() if k != "root"}
    root = msg_tree["root"]
    found = genmsg.deps.find_msg_dependencies_with_type("demo", str(root / "demo/msg/Path.msg"), paths)
    assert sorted(found) == [("demo/Point", str(root / "demo/msg/Point.msg")),
                             ("std_msgs/Header", str(root / "std_msgs/msg/Header.msg"))]
    assert genmsg.deps.find_msg_dependencies("demo", str(root / "demo/msg/Point.msg"), paths) == []
    srv = genmsg.deps.find_srv_dependencies("demo", str(root / "demo/srv/Plan.srv"), paths)
    assert sorted(srv) == sorted([str(root / "demo/msg/Point.msg"), str(root / "demo/msg/Path.msg"),
                                  str(root / "std_msgs/msg/Header.msg")])
    with pytest.raises(genmsg.msg_loader.MsgNotFound, match="NoSuch"):
        genmsg.deps.find_msg_dependencies("demo", str(root / "demo/msg/Missing.msg"), paths)
    with pytest.raises(genmsg.MsgGenerationException, match="Cannot read .msg for demo/Broken"):
        genmsg.deps.find_msg_dependencies("demo", str(root / "demo/msg/Broken.msg"), paths)


@pytest.mark.slow
def test_roslaunch_logs_without_a_master(tmp_path: Path):
    env = {"PATH": "/usr/bin:/bin", "ROS_MASTER_URI": "http://127.0.0.1:9/",
           "ROS_LOG_DIR": str(tmp_path / "logs"), "HOME": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", "from roslaunch.roslaunch_logs import logs_main; logs_main()"],
                         env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert out.stderr.strip() == "No active roscore"
    assert out.stdout.strip() == str(tmp_path / "logs")
    bad = subprocess.run([sys.executable, "-c", "import sys; sys.argv=['roslaunch-logs', 'x']; "
                          "from roslaunch.roslaunch_logs import logs_main; logs_main()"],
                         env=env, capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "takes no arguments" in bad.stderr


def test_rosunit_pmon_is_the_launchers_monitor():
    import roslaunch.pmon

    assert rosunit.pmon.ProcessMonitor is roslaunch.pmon.ProcessMonitor
    assert rosunit.pmon.PmonException is RLException
    assert issubclass(rosunit.pmon.FatalProcessLaunch, rosunit.pmon.PmonException)
