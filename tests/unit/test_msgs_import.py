"""User packages on ROS_PACKAGE_PATH import as <pkg>.msg / <pkg>.srv; stub packages on disk."""

from __future__ import annotations

from pathlib import Path

import pytest

from minros.msgs import write_stub_package
from support import run_python


def _make_package(root: Path, name: str = "my_pkg") -> Path:
    pkg = root / name
    (pkg / "msg").mkdir(parents=True)
    (pkg / "srv").mkdir()
    (pkg / "package.xml").write_text(f"<package format='2'><name>{name}</name></package>\n")
    (pkg / "msg" / "Num.msg").write_text("int64 num\nHeader header\ngeometry_msgs/Point[] pts\n")
    (pkg / "msg" / "Pair.msg").write_text("Num a\nNum b\n")
    (pkg / "srv" / "AddTwo.srv").write_text("int64 a\nint64 b\n---\nint64 sum\n")
    return pkg


@pytest.mark.slow
def test_import_hook_finds_user_packages(tmp_path: Path) -> None:
    _make_package(tmp_path / "src")
    code = (
        "import minros.msgs\nminros.msgs.install_import_hook()\n"
        "from my_pkg.msg import Num, Pair\n"
        "from my_pkg.srv import AddTwo, AddTwoRequest, AddTwoResponse\n"
        "import my_pkg.msg as m\n"
        "n = Num(num=5); n.pts = [__import__('geometry_msgs.msg').msg.Point(1, 2, 3)]\n"
        "assert Num().deserialize(n.serialize_to_bytes()) == n\n"
        "assert AddTwo._request_class is AddTwoRequest and AddTwoResponse(3).sum == 3\n"
        "assert Pair._type == 'my_pkg/Pair' and sorted(m.__all__) == ['Num', 'Pair']\n"
        "print(Num._type, AddTwo._md5sum)\n"
    )
    out = run_python(code, {"ROS_PACKAGE_PATH": str(tmp_path / "src")})
    assert out.returncode == 0, out.stderr
    # same text as rospy_tutorials/AddTwoInts, so the same md5 sum
    assert out.stdout.split() == ["my_pkg/Num", "6a2e34150c00229791cc89ff309fff21"]


@pytest.mark.slow
def test_import_hook_leaves_other_imports_alone(tmp_path: Path) -> None:
    _make_package(tmp_path / "src")
    code = (
        "import minros.msgs, importlib\nminros.msgs.install_import_hook()\n"
        "for name in ('no_such_module_xyz', 'my_pkg.nothing', 'std_msgs.msg.Nope'):\n"
        "    try:\n"
        "        importlib.import_module(name)\n"
        "    except ImportError:\n"
        "        pass\n"
        "    else:\n"
        "        raise SystemExit('imported ' + name)\n"
        "try:\n"
        "    from my_pkg.msg import Missing\n"
        "except ImportError as exc:\n"
        "    print('ok', exc)\n"
    )
    out = run_python(code, {"ROS_PACKAGE_PATH": str(tmp_path / "src")})
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("ok cannot import name 'Missing'")


@pytest.mark.slow
def test_write_stub_package(tmp_path: Path) -> None:
    _make_package(tmp_path / "src")
    devel = tmp_path / "devel" / "lib" / "python3" / "dist-packages"
    root = write_stub_package("my_pkg", devel)
    assert (root / "__init__.py").is_file() and (root / "msg" / "__init__.py").is_file()
    assert (root / "srv" / "__init__.py").is_file()
    # a real module is never overwritten
    (root / "srv" / "__init__.py").write_text("REAL = 1\n")
    write_stub_package("my_pkg", devel)
    assert (root / "srv" / "__init__.py").read_text() == "REAL = 1\n"
    (root / "srv" / "__init__.py").unlink()
    write_stub_package("my_pkg", devel)
    # the stubs work without the import hook having been installed first
    code = ("from my_pkg.msg import Num\nfrom my_pkg.srv import AddTwoRequest\n"
            "print(Num.__module__, AddTwoRequest._type)\n")
    out = run_python(code, {"ROS_PACKAGE_PATH": str(tmp_path / "src"), "PYTHONPATH": str(devel)})
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["my_pkg.msg", "my_pkg/AddTwoRequest"]


@pytest.mark.slow
def test_bundled_stub_packages_import_without_ros() -> None:
    code = ("from std_msgs.msg import String\nfrom std_srvs.srv import Empty, EmptyResponse\n"
            "from turtlesim.srv import Spawn, SpawnRequest\nfrom rospy_tutorials.srv import AddTwoInts\n"
            "from sensor_msgs.msg import Image\nfrom rosgraph_msgs.msg import Clock, Log\n"
            "import io; b = io.BytesIO(); String('x').serialize(b); print(b.getvalue().hex())\n")
    out = run_python(code, {"ROS_PACKAGE_PATH": ""})
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "0100000078"


def test_missing_embedded_type_names_the_user(tmp_path: Path, monkeypatch) -> None:
    import pytest

    from minros.msgs import UnknownTypeError, get_message_class

    pkg = _make_package(tmp_path / "src", "typo_pkg")
    (pkg / "msg" / "Typo.msg").write_text("int32 a\nPionts p\n")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "src"))
    with pytest.raises(UnknownTypeError) as info:
        get_message_class("typo_pkg/Typo")
    text = str(info.value)
    assert text.startswith(f"{pkg / 'msg' / 'Typo.msg'}:2: field [p] of typo_pkg/Typo has "
                           "unknown type [typo_pkg/Pionts]: no file msg/Pionts.msg")


@pytest.mark.slow
def test_misspelled_field_type_says_which_type_file_and_line(tmp_path: Path) -> None:
    """``from pkg.msg import M`` names the unknown type, the file and line that use it, and
    the likely fix, where Python would say "cannot import name 'M' ... (unknown location)"."""
    pkg = _make_package(tmp_path / "src", "typo_pkg")
    (pkg / "msg" / "M.msg").write_text("int32 a\n# the name\nstrin data\n")
    (pkg / "msg" / "Outer.msg").write_text("Num n\nM m\n")
    (pkg / "srv" / "S.srv").write_text("int32 a\n---\nfloat65 b\n")
    code = (
        "import rospy\n"
        "for stmt in ('from typo_pkg.msg import M', 'from typo_pkg.msg import Outer',\n"
        "             'from typo_pkg.srv import S', 'from typo_pkg.srv import SResponse'):\n"
        "    try:\n"
        "        exec(stmt)\n"
        "    except ImportError as exc:\n"
        "        print(exc)\n"
        "import typo_pkg.msg\n"
        "print(hasattr(typo_pkg.msg, 'Nope'))\n"
        "from typo_pkg.msg import Num\n"  # the package's sound types still import
        "print(Num._type)\n"
    )
    out = run_python(code, {"ROS_PACKAGE_PATH": str(tmp_path / "src")})
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    msg, srv = pkg / "msg" / "M.msg", pkg / "srv" / "S.srv"
    assert lines[0] == (f"cannot import name 'M' from 'typo_pkg.msg': {msg}:3: field [data] of "
                        "typo_pkg/M has unknown type [typo_pkg/strin]: no file msg/strin.msg in "
                        f"package [typo_pkg] ({pkg}); did you mean [string]?")
    assert lines[1].startswith(f"cannot import name 'Outer' from 'typo_pkg.msg': {msg}:3: ")
    assert lines[1].endswith("did you mean [string]? (needed by typo_pkg/Outer)")
    for line, name in zip(lines[2:4], ("S", "SResponse")):
        assert line.startswith(f"cannot import name '{name}' from 'typo_pkg.srv': {srv}:3: field "
                               "[b] of typo_pkg/SResponse has unknown type [typo_pkg/float65]")
        assert line.endswith("did you mean [float64]?")
    assert lines[4:] == ["False", "typo_pkg/Num"]


def test_action_files_generate_messages_like_genaction(tmp_path: Path, monkeypatch) -> None:
    from minros.msgs import get_message_class
    from minros.msgs.registry import list_types
    from minros.packages import BUILTIN_SHARE_DIRS

    # the bundled nav_msgs ships Debian's generated files: our generator must agree byte for byte
    pkg = _make_package(tmp_path / "src", "act_pkg")
    (pkg / "action").mkdir()
    share = BUILTIN_SHARE_DIRS[0]
    for source, name in (("nav_msgs", "GetMap"), ("tf2_msgs", "LookupTransform")):
        (pkg / "action" / f"{name}.action").write_bytes(
            (share / source / "action" / f"{name}.action").read_bytes())
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "src"))
    for source, name in (("nav_msgs", "GetMap"), ("tf2_msgs", "LookupTransform")):
        for suffix in ("Action", "ActionGoal", "ActionResult", "ActionFeedback", "Goal", "Result",
                       "Feedback"):
            ours = get_message_class(f"act_pkg/{name}{suffix}")
            debian = get_message_class(f"{source}/{name}{suffix}")
            assert ours._md5sum == debian._md5sum
            assert ours._full_text.replace("act_pkg/", f"{source}/") == debian._full_text
    assert "act_pkg/GetMapActionGoal" in list_types("act_pkg")
