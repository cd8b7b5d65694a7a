""".action files: the seven generated types equal genaction's (actionlib's bundled Test,
TestRequest and TwoInts, whose Debian-generated .msg files ship alongside), packages with only
action/ import as <pkg>.msg, and catkin_make's add_action_files."""

from __future__ import annotations

from pathlib import Path

import pytest

from support import run_python

SUFFIXES = ("Action", "ActionGoal", "ActionResult", "ActionFeedback", "Goal", "Result", "Feedback")
FIBONACCI = "#goal definition\nint32 order\n---\n#result definition\nint32[] sequence\n---\n#feedback\nint32[] sequence\n"


def _action_package(root: Path, name: str, actions: dict) -> Path:
    pkg = root / name
    (pkg / "action").mkdir(parents=True)
    (pkg / "package.xml").write_text(f"<package format='2'><name>{name}</name></package>\n")
    for stem, text in actions.items():
        (pkg / "action" / f"{stem}.action").write_text(text)
    return pkg


@pytest.mark.parametrize("action", ["Test", "TestRequest", "TwoInts"])
def test_actionlib_actions_generate_debians_messages(tmp_path: Path, monkeypatch, action: str) -> None:
    from minros.msgs import get_message_class
    from minros.packages import BUILTIN_SHARE_DIRS

    share = BUILTIN_SHARE_DIRS[0] / "actionlib"
    _action_package(tmp_path, "gen_check", {action: (share / "action" / f"{action}.action").read_text()})
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    for suffix in SUFFIXES:
        ours = get_message_class(f"gen_check/{action}{suffix}")
        debian = get_message_class(f"actionlib/{action}{suffix}")  # Debian's generated .msg file
        assert (share / "msg" / f"{action}{suffix}.msg").is_file()
        assert ours._md5sum == debian._md5sum
        assert ours._full_text.replace("gen_check/", "actionlib/") == debian._full_text


def test_known_md5_sums_of_the_bundled_actions() -> None:
    import actionlib.msg as m

    # as Debian's python3-actionlib generated classes carry them
    assert m.TwoIntsAction._md5sum == "6d1aa538c4bd6183a2dfb7fcac41ee50"
    assert m.TestAction._md5sum == "991e87a72802262dfbe5d1b3cf6efc9a"
    assert m.TwoIntsActionGoal._md5sum == "684a2db55d6ffb8046fb9d6764ce0860"


@pytest.mark.slow
def test_package_with_only_actions_imports_as_msg(tmp_path: Path) -> None:
    _action_package(tmp_path / "src", "actionlib_tutorials", {"Fibonacci": FIBONACCI})
    out = run_python("import rospy\nfrom actionlib_tutorials.msg import FibonacciAction, FibonacciGoal\n"
                     "import actionlib_tutorials.msg as m\n"
                     "print(FibonacciAction._md5sum, FibonacciGoal(order=3).order, len(m.__all__))\n",
                     {"ROS_PACKAGE_PATH": str(tmp_path / "src")})
    assert out.returncode == 0, out.stderr
    # the md5 sum ROS gives actionlib_tutorials/FibonacciAction
    assert out.stdout == "f59df5767bf7634684781c92598b2406 3 7\n"


@pytest.mark.slow
def test_catkin_make_add_action_files(tmp_path: Path) -> None:
    from minros.workspace import catkin

    ws = tmp_path / "ws"
    pkg = _action_package(ws / "src", "actionlib_tutorials", {"Fibonacci": FIBONACCI})
    lines: list = []
    catkin.make_workspace(ws, out=lines.append)
    assert "-- actionlib_tutorials: 7 messages, 0 services" in lines
    assert (f"Generating .msg files for action actionlib_tutorials/Fibonacci "
            f"{pkg / 'action' / 'Fibonacci.action'}") in lines
    devel = ws / "devel" / "lib" / "python3" / "dist-packages"
    out = run_python("from actionlib_tutorials.msg import FibonacciActionFeedback as F\nprint(F._type)",
                     {"PYTHONPATH": str(devel), "ROS_PACKAGE_PATH": str(ws / "src")})
    assert out.returncode == 0, out.stderr
    assert out.stdout == "actionlib_tutorials/FibonacciActionFeedback\n"
    (pkg / "action" / "Broken.action").write_text("int32 order\n---\nint32[] sequence\n")
    with pytest.raises(catkin.WorkspaceError) as err:
        catkin.make_workspace(ws, out=lambda s: None)
    text = str(err.value)
    assert text.startswith(f"{pkg / 'action' / 'Broken.action'}: ") and "\n" not in text
    assert "found 1" in text
