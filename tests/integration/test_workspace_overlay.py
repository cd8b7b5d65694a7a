"""A workspace behaves as a catkin devel space: its packages come first, for their Python
modules, their programs and their files, also where minros ships a package of the same name;
and an overlay package falls back to its underlay for what it lacks (a message, a ``srv/``
folder, a library module), as ROS's devel spaces (their ``__init__`` extends ``__path__``) and
message lookup do.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

from minros.workspace import catkin
from support import PYTHON

BIN = Path(PYTHON).parent


def _env(tmp_path: Path) -> dict:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("ROS_") and k not in ("PYTHONPATH", "CMAKE_PREFIX_PATH")}
    env.update({"PATH": f"{BIN}:/usr/bin:/bin", "HOME": str(tmp_path),
                "ROS_HOME": str(tmp_path / "ros_home")})
    return env


def _in_workspace(ws: Path, command: str, tmp_path: Path) -> str:
    out = subprocess.run(["bash", "-c", f"source devel/setup.bash && cd / && {command}"],
                         cwd=ws, env=_env(tmp_path), capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stdout + out.stderr
    return out.stdout


def _workspace(tmp_path: Path, name: str = "ws") -> Path:
    ws = tmp_path / name
    (ws / "src").mkdir(parents=True)
    return ws


def _make(ws: Path) -> list:
    lines: list = []
    catkin.make_workspace(ws, out=lines.append)
    return lines


def test_the_workspaces_python_package_comes_before_the_one_minros_ships(tmp_path: Path):
    ws = _workspace(tmp_path)
    pkg = catkin.create_package("joint_state_publisher", ["rospy"], ws / "src", out=lambda s: None)
    module = pkg / "src" / "joint_state_publisher"
    module.mkdir(parents=True)
    (module / "__init__.py").write_text("MINE = 'workspace'\n")
    (module / "extra.py").write_text("VALUE = 7\n")
    lines = _make(ws)
    assert ("-- joint_state_publisher: the workspace's package comes before minros's "
            "'joint_state_publisher'; what it lacks comes from minros's") in lines
    printed = _in_workspace(ws, "python -c 'import joint_state_publisher as j, "
                                "joint_state_publisher.extra as e; print(j.MINE, e.VALUE)'",
                            tmp_path)
    assert printed.split() == ["workspace", "7"]


def test_a_package_of_only_actions_keeps_the_library_of_its_name(tmp_path: Path):
    """A workspace ``actionlib`` holding actions only: its messages import from the workspace
    and minros's actionlib (SimpleActionClient, its modules) stays, as an underlay."""
    ws = _workspace(tmp_path)
    pkg = catkin.create_package("actionlib", ["rospy"], ws / "src", out=lambda s: None)
    (pkg / "action").mkdir()
    (pkg / "action" / "Count.action").write_text("int32 to\n---\nint32 reached\n---\nint32 at\n")
    dist = ws / "devel" / "lib" / "python3" / "dist-packages"
    # what an earlier catkin_make wrote there: the empty stand-in that hid the library
    (dist / "actionlib" / "msg").mkdir(parents=True)
    (dist / "actionlib" / "__init__.py").write_text(
        '"""actionlib: message package stand-in provided by minros."""\n')
    _make(ws)
    printed = _in_workspace(
        ws, "python -c 'import actionlib, actionlib.simple_action_server; "
            "from actionlib.msg import CountGoal, CountAction, TestAction; "
            "print(actionlib.SimpleActionClient.__name__, CountGoal(to=3).to, CountAction._type, "
            "TestAction._type)'", tmp_path)
    # TestAction: one of actionlib's own actions, which the workspace package does not have
    assert printed.split() == ["SimpleActionClient", "3", "actionlib/CountAction",
                               "actionlib/TestAction"]
    # one the user wrote there is theirs: left alone
    (dist / "actionlib" / "__init__.py").write_text("HAND_WRITTEN = 1\n")
    _make(ws)
    assert (dist / "actionlib" / "__init__.py").read_text() == "HAND_WRITTEN = 1\n"


def test_an_overlay_without_a_srv_folder_does_not_hide_its_underlays_services(tmp_path: Path):
    """Two workspaces, the overlay's package with messages only: its .srv module is the
    underlay's, and a message the overlay lacks is the underlay's too."""
    under = _workspace(tmp_path, "under")
    pkg = catkin.create_package("layered_msgs", ["std_msgs"], under / "src", out=lambda s: None)
    (pkg / "msg").mkdir()
    (pkg / "msg" / "Base.msg").write_text("int32 base\n")
    (pkg / "srv").mkdir()
    (pkg / "srv" / "Ask.srv").write_text("int32 q\n---\nint32 a\n")
    _make(under)
    over = _workspace(tmp_path, "over")
    pkg = catkin.create_package("layered_msgs", ["std_msgs"], over / "src", out=lambda s: None)
    (pkg / "msg").mkdir()
    (pkg / "msg" / "Extra.msg").write_text("string extra\n")
    _make(over)
    printed = _in_workspace(
        over, f"source {under}/devel/setup.bash && source {over}/devel/setup.bash && "
              "python -c 'from layered_msgs.msg import Extra, Base; "
              "from layered_msgs.srv import Ask, AskRequest; "
              "print(Extra._type, Base._type, Ask._type, AskRequest(q=2).q)'", tmp_path)
    assert printed.split() == ["layered_msgs/Extra", "layered_msgs/Base", "layered_msgs/Ask", "2"]


def test_on_ros_package_path_alone_an_overlay_falls_back_too(tmp_path: Path):
    """No build at all: the first folder of a name on ROS_PACKAGE_PATH lacks srv/; rosmsg's
    lookup and the import hook take the service from the next folder of that name."""
    for root, kind, text in ((tmp_path / "a", "msg", "int8 x\n"),
                             (tmp_path / "b", "srv", "int8 x\n---\nint8 y\n")):
        pkg = root / "fallback_msgs"
        (pkg / kind).mkdir(parents=True)
        (pkg / "package.xml").write_text("<package format='2'><name>fallback_msgs</name>"
                                         "<version>1.0.0</version></package>\n")
        (pkg / kind / f"Thing.{kind}").write_text(text)
    env = _env(tmp_path)
    env["ROS_PACKAGE_PATH"] = f"{tmp_path / 'a'}:{tmp_path / 'b'}"
    out = subprocess.run([PYTHON, "-c", "from fallback_msgs.srv import Thing\n"
                                        "from fallback_msgs.msg import Thing as M\n"
                                        "print(Thing._type, M._type)"],
                         env=env, capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["fallback_msgs/Thing", "fallback_msgs/Thing"]
    shown = subprocess.run([str(BIN / "rossrv"), "show", "fallback_msgs/Thing"], env=env,
                           capture_output=True, text=True, timeout=60)
    assert shown.stdout == "int8 x\n---\nint8 y\n\n", shown.stderr


def test_the_workspaces_programs_and_files_come_first(tmp_path: Path):
    """rosrun runs the workspace's talker.py, falls back to minros's for a program the
    workspace package lacks, and $(find)/rospack find give the workspace's folder."""
    ws = _workspace(tmp_path)
    pkg = catkin.create_package("rospy_tutorials", ["rospy"], ws / "src", out=lambda s: None)
    (pkg / "scripts").mkdir()
    talker = pkg / "scripts" / "talker.py"
    talker.write_text("#!/usr/bin/env python\nprint('the workspace talker')\n")
    talker.chmod(0o755)
    _make(ws)
    assert _in_workspace(ws, "rosrun rospy_tutorials talker.py", tmp_path) == \
        "the workspace talker\n"
    assert _in_workspace(ws, "rospack find rospy_tutorials", tmp_path).strip() == str(pkg)
    # listener.py: the workspace package has none, so minros's runs
    resolved = _in_workspace(ws, "python -c 'from minros.workspace.executables import "
                                 "resolve_executable as r; print(r(\"rospy_tutorials\", "
                                 "\"listener.py\")[-1])'", tmp_path)
    assert resolved.strip() == "minros.nodes.rospy_tutorials.listener"
