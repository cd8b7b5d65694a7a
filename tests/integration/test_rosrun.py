"""rosrun and rospack as processes: search, interpreter choice, argument passing, error texts."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from support import Proc, ros_env

BIN = Path(sys.executable).parent

SCRIPT = """#!/usr/bin/env python
import sys
print("exe", sys.executable)
print("argv", sys.argv[1:])
"""


@pytest.fixture
def pkg_path(tmp_path: Path) -> Path:
    """A package source tree on ROS_PACKAGE_PATH with scripts at several depths."""
    pkg = tmp_path / "src" / "demo_pkg"
    (pkg / "scripts" / "deep").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2"><name>demo_pkg</name><version>0.0.0</version>'
        "<description>d</description><maintainer email='a@b.c'>a</maintainer><license>BSD</license>"
        "<buildtool_depend>catkin</buildtool_depend></package>\n")
    node = pkg / "scripts" / "deep" / "node.py"
    node.write_text(SCRIPT)
    node.chmod(0o755)
    (pkg / "scripts" / "plain.py").write_text(SCRIPT)  # no executable bit
    shell = pkg / "scripts" / "hello.sh"
    shell.write_text("#!/bin/sh\necho shell says $1\n")
    shell.chmod(0o755)
    return tmp_path / "src"


def _run(args, env, **kw):
    return subprocess.run([str(BIN / args[0])] + list(args[1:]), env=env, capture_output=True,
                          text=True, timeout=30, **kw)


def _env(tmp_path: Path, pkg_path: Path):
    env = ros_env(None, tmp_path / "home", {"ROS_PACKAGE_PATH": str(pkg_path)})
    env["PATH"] = "/usr/bin:/bin"  # rosrun must bring its own interpreter onto PATH
    return env


def test_rosrun_finds_nested_python_script_and_passes_remaps(tmp_path, pkg_path):
    out = _run(["rosrun", "demo_pkg", "node.py", "chatter:=/other", "_rate:=5", "plain"],
               _env(tmp_path, pkg_path))
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    # the venv's interpreter (python or python3 of the same bin folder), not the system one
    assert Path(lines[0].split(" ", 1)[1]).parent == Path(sys.executable).parent
    assert lines[1] == "argv ['chatter:=/other', '_rate:=5', 'plain']"


def test_rosrun_runs_non_python_executable(tmp_path, pkg_path):
    out = _run(["rosrun", "demo_pkg", "hello.sh", "there"], _env(tmp_path, pkg_path))
    assert out.returncode == 0 and out.stdout == "shell says there\n"


def test_rosrun_path_form(tmp_path, pkg_path):
    out = _run(["rosrun", "demo_pkg", "scripts/deep/node.py"], _env(tmp_path, pkg_path))
    assert out.returncode == 0 and out.stdout.startswith("exe ")
    bad = _run(["rosrun", "demo_pkg", "scripts/plain.py"], _env(tmp_path, pkg_path))
    assert bad.returncode == 3
    assert bad.stdout == f"[rosrun] Couldn't find executable named {pkg_path / 'demo_pkg' / 'scripts/plain.py'}\n"


def test_rosrun_script_without_exec_bit(tmp_path, pkg_path):
    out = _run(["rosrun", "demo_pkg", "plain.py"], _env(tmp_path, pkg_path))
    assert out.returncode == 3
    pkg = pkg_path / "demo_pkg"
    assert out.stdout.splitlines() == [
        f"[rosrun] Couldn't find executable named plain.py below {pkg}",
        "[rosrun] Found the following, but they're either not files,",
        "[rosrun] or not executable:",
        f"[rosrun]   {pkg / 'scripts' / 'plain.py'}",
    ]


def test_rosrun_unknown_executable_and_package(tmp_path, pkg_path):
    env = _env(tmp_path, pkg_path)
    out = _run(["rosrun", "demo_pkg", "nothing.py"], env)
    assert out.returncode == 3
    assert out.stdout == f"[rosrun] Couldn't find executable named nothing.py below {pkg_path / 'demo_pkg'}\n"
    out = _run(["rosrun", "no_such_pkg", "x"], env)
    assert out.returncode == 2
    assert out.stderr == "[rospack] Error: package 'no_such_pkg' not found\n"
    assert "Traceback" not in out.stderr + out.stdout


@pytest.mark.smoke
def test_rosrun_usage(tmp_path, pkg_path):
    out = _run(["rosrun", "demo_pkg"], _env(tmp_path, pkg_path))
    assert out.returncode == 0 and out.stdout.startswith("Usage: rosrun [--prefix cmd]")


def test_rosrun_builtin_missing_module_is_one_line(monkeypatch):
    from minros.workspace import executables

    monkeypatch.setitem(executables.BUILTIN_NODES, "rospy_tutorials", {"ghost": "minros.no_such.module"})
    with pytest.raises(executables.ExecutableError) as err:
        executables.resolve_executable("rospy_tutorials", "ghost")
    assert err.value.lines == ["[rosrun] ghost of package rospy_tutorials is not available in this version of minros"]


def test_rosrun_builtin_tutorial_resolves_to_module():
    from minros.workspace import executables

    assert executables.resolve_executable("rospy_tutorials", "talker.py") == [
        sys.executable, "-m", "minros.nodes.rospy_tutorials.talker"]


def test_rospack_find_and_list(tmp_path, pkg_path):
    env = _env(tmp_path, pkg_path)
    out = _run(["rospack", "find", "demo_pkg"], env)
    assert out.returncode == 0 and out.stdout == f"{pkg_path / 'demo_pkg'}\n"
    listed = _run(["rospack", "list"], env).stdout.splitlines()
    assert f"demo_pkg {pkg_path / 'demo_pkg'}" in listed
    assert any(line.startswith("std_msgs ") for line in listed)
    assert [line.split()[0] for line in listed] == sorted(line.split()[0] for line in listed)
    missing = _run(["minros", "pkg", "find", "ghost_pkg"], env)
    assert missing.returncode == 1 and missing.stderr == "[rospack] Error: package 'ghost_pkg' not found\n"


#: packages minros provides and their versions, which are Debian's ROS's
PROVIDED = {"roslaunch": "1.15.15", "rospy": "1.15.15", "rosbag": "1.15.15", "roslib": "1.15.8",
            "genpy": "0.6.16", "tf": "1.13.2", "actionlib": "1.14.0", "turtlesim": "0.10.2",
            "diagnostic_updater": "1.11.0", "cv_bridge": "1.16.2"}


def test_rosversion_and_rospack_know_the_packages_minros_provides(tmp_path):
    env = ros_env(None, tmp_path / "home")  # no ROS_PACKAGE_PATH at all
    for package, version in PROVIDED.items():
        out = _run(["rosversion", package], env)
        assert (out.returncode, out.stdout) == (0, f"{version}\n"), (package, out.stderr)
        found = _run(["rospack", "find", package], env)
        assert found.returncode == 0 and (Path(found.stdout.strip()) / "package.xml").is_file()
    assert _run(["rosversion", "-d"], env).stdout == "noetic\n"
    assert _run(["rosversion", "-d"], dict(env, ROS_DISTRO="melodic")).stdout == "melodic\n"
    assert _run(["rosversion", "-s", "rosbag"], env).stdout == "1.15.15"
    missing = _run(["rosversion", "nope_pkg"], env)
    assert (missing.returncode, missing.stdout) == (1, "Cannot locate [nope_pkg]\n")
    usage = _run(["rosversion"], env)
    assert usage.returncode == 2 and "one of the arguments package -d/--distro -a/--all" in usage.stderr
    listed = _run(["rosversion", "-a"], env).stdout.splitlines()
    assert "roslaunch: 1.15.15" in listed and "std_msgs: 0.5.13" in listed
    loaded = _run(["python", "-c", "import roslib; roslib.load_manifest('rosbag'); "
                   "roslib.load_manifest('geometry_msgs'); print('loaded')"], env)
    assert loaded.stdout == "loaded\n", loaded.stderr


def test_catkin_commands_as_processes(tmp_path):
    env = dict(os.environ)
    ws = tmp_path / "ws"
    (ws / "src").mkdir(parents=True)
    init = _run(["catkin_init_workspace"], env, cwd=ws / "src")
    assert init.returncode == 0 and "Creating symlink" in init.stdout
    again = _run(["catkin_init_workspace"], env, cwd=ws / "src")
    assert again.returncode == 1 and again.stderr.startswith("catkin_init_workspace: error: File ")
    create = _run(["minros", "ws", "create_pkg", "pkg_a", "rospy"], env, cwd=ws / "src")
    assert create.returncode == 0 and "Created file pkg_a/package.xml" in create.stdout
    make = _run(["catkin_make"], env, cwd=ws)
    assert make.returncode == 0 and "-- ~~  - pkg_a" in make.stdout
    nosrc = _run(["catkin_make"], env, cwd=tmp_path)
    assert nosrc.returncode == 1 and "does not exist" in nosrc.stderr and "Traceback" not in nosrc.stderr


def test_rosrun_builtin_rospy_tutorials_talker_listener(minros_master, ros_home):
    env = ros_env(minros_master, ros_home)
    talker = Proc([str(BIN / "rosrun"), "rospy_tutorials", "talker.py"], env)
    listener = Proc([str(BIN / "rosrun"), "rospy_tutorials", "listener.py", "chatter:=chatter"], env)
    try:
        said = talker.read_until("hello world", timeout=20)
        heard = listener.read_until("I heard hello world", timeout=20)
    finally:
        listener.stop()
        talker.stop()
    assert "[INFO]" in said
    assert "/listener_" in heard  # anonymous node name, as the tutorial's init_node(anonymous=True)


def test_rosrun_builtin_add_two_ints(minros_master, ros_home):
    env = ros_env(minros_master, ros_home)
    server = Proc([str(BIN / "rosrun"), "rospy_tutorials", "add_two_ints_server"], env)
    try:
        server.read_until("Ready to add Two Ints.", timeout=20)
        client = subprocess.run([str(BIN / "rosrun"), "rospy_tutorials", "add_two_ints_client", "3", "4"],
                                env=env, capture_output=True, text=True, timeout=30)
        assert client.returncode == 0, client.stderr
        assert client.stdout.splitlines()[-1] == "3 + 4 = 7"
        server_out = server.read_until("Returning", timeout=10)
        assert "Returning [3 + 4 = 7]" in server_out
        usage = subprocess.run([str(BIN / "rosrun"), "rospy_tutorials", "add_two_ints_client", "x"],
                               env=env, capture_output=True, text=True, timeout=30)
        assert usage.returncode == 1 and "[x y]" in usage.stdout
    finally:
        server.stop()


def test_rosrun_non_unique_executable_asks_which(tmp_path, pkg_path):
    other = pkg_path / "demo_pkg" / "other"
    other.mkdir()
    (other / "node.py").write_text(SCRIPT.replace('"exe"', '"other-exe"'))
    (other / "node.py").chmod(0o755)
    env = _env(tmp_path, pkg_path)
    out = _run(["rosrun", "demo_pkg", "node.py", "x"], env, input="2\n")
    lines = out.stdout.splitlines()
    assert lines[0] == "[rosrun] You have chosen a non-unique executable, please pick one of the following:"
    assert lines[1] == f"1) {other / 'node.py'}"
    assert lines[3].startswith("#? exe ") and lines[4] == "argv ['x']"  # the second: scripts/deep/node.py
    aborted = _run(["rosrun", "demo_pkg", "node.py"], env, input="")
    assert aborted.returncode == 1


def test_every_shipped_program_runs_under_its_ros_package_name() -> None:
    """roslaunch and rosrun start each executable minros ships as ROS installs it (the tools
    too: rostopic, rosbag, rosmsg, rosconsole, ...): every table entry is a module that runs
    as a program and answers -h."""
    import importlib.util

    from minros.workspace import executables

    missing = [f"{pkg}/{exe}: {module}" for pkg, table in executables.BUILTIN_NODES.items()
               for exe, module in table.items() if importlib.util.find_spec(module) is None]
    assert missing == []
    for pkg, exe in (("rostopic", "rostopic"), ("rosnode", "rosnode"), ("rosparam", "rosparam"),
                     ("rosservice", "rosservice"), ("rosmsg", "rosmsg"), ("rosbag", "rosbag"),
                     ("rosconsole", "rosconsole"), ("rostest", "rostest")):
        argv = executables.resolve_executable(pkg, exe)
        assert argv[1:3] == ["-m", executables.BUILTIN_NODES[pkg][exe]]
        run = subprocess.run(argv + ["-h"], capture_output=True, text=True, timeout=60)
        assert pkg in (run.stdout + run.stderr).lower(), (pkg, run.stdout, run.stderr)
        assert "Traceback" not in run.stderr, run.stderr
