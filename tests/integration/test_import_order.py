"""Message packages on ROS_PACKAGE_PATH import before rospy does, as a devel space makes them.

A node that does ``from my_pkg.srv import AddTwoInts`` (ros_comm's test nodes do, with
``from test_rosmaster.srv import *``) before ``import rospy`` died with ModuleNotFoundError:
the message importer was installed by rospy. The start-up hook minros installs
(``minros_import_hook.pth`` -> ``_minros_import_hook``) answers for such packages in any
interpreter of the environment, and for nothing else.
"""

from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
from pathlib import Path

from support import PYTHON


def _package(root: Path, name: str) -> Path:
    pkg = root / name
    (pkg / "srv").mkdir(parents=True)
    (pkg / "msg").mkdir()
    (pkg / "package.xml").write_text(f"<package format='2'><name>{name}</name>"
                                     "<version>1.0.0</version></package>\n")
    (pkg / "srv" / "AddTwoInts.srv").write_text("int64 a\nint64 b\n---\nint64 sum\n")
    (pkg / "msg" / "Num.msg").write_text("int64 num\n")
    return pkg


def _run(code: str, cwd: Path, **env: str) -> subprocess.CompletedProcess:
    full = {k: v for k, v in os.environ.items() if not k.startswith("ROS_") and k != "PYTHONPATH"}
    full.update(env)
    return subprocess.run([PYTHON, "-c", code], cwd=cwd, env=full, capture_output=True,
                          text=True, timeout=60)


def test_the_start_up_hook_is_installed_with_minros():
    site = Path(sysconfig.get_paths()["purelib"])
    pth = site / "minros_import_hook.pth"
    assert pth.is_file(), f"{pth} missing: reinstall minros (pip install -e .)"
    assert "_minros_import_hook" in pth.read_text()


def test_a_service_imports_before_rospy(tmp_path: Path):
    _package(tmp_path / "ws", "order_test_msgs")
    out = _run("from order_test_msgs.srv import AddTwoInts, AddTwoIntsRequest\n"
               "from order_test_msgs.msg import Num\n"
               "import sys\n"
               "assert 'rospy' not in sys.modules\n"
               "import rospy\n"
               "print(AddTwoInts._type, AddTwoIntsRequest(1, 2).b, Num(num=4).num)\n",
               tmp_path, ROS_PACKAGE_PATH=str(tmp_path / "ws"))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["order_test_msgs/AddTwoInts", "2", "4"]


def test_star_import_of_a_srv_module_first(tmp_path: Path):
    """``from test_rosmaster.srv import *`` is the first line of ros_comm's test servers."""
    _package(tmp_path / "ws", "star_test_msgs")
    out = _run("from star_test_msgs.srv import *\nprint(AddTwoInts._type, AddTwoIntsResponse(3).sum)",
               tmp_path, ROS_PACKAGE_PATH=str(tmp_path / "ws"))
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["star_test_msgs/AddTwoInts", "3"]


def test_the_hook_answers_only_for_packages_the_environment_names(tmp_path: Path):
    _package(tmp_path / "ws", "named_msgs")
    code = ("import sys\n"
            "try:\n    import not_a_ros_package_at_all\nexcept ModuleNotFoundError as e:\n"
            "    print('missing', e.name)\n"
            # a package minros ships has its stand-in; the hook leaves it to that
            "import std_msgs.msg\nprint(type(std_msgs.msg.__spec__.loader).__name__)\n"
            "print('minros.msgs.registry' in sys.modules)\n")
    out = _run(code, tmp_path, ROS_PACKAGE_PATH=str(tmp_path / "ws"))
    assert out.returncode == 0, out.stderr
    lines = out.stdout.split("\n")
    assert lines[0] == "missing not_a_ros_package_at_all"
    assert lines[1] != "_NamespaceLoader"
    # without ROS_PACKAGE_PATH the hook answers nothing and imports nothing of minros
    out = _run("import sys\ntry:\n    import named_msgs.srv\nexcept ModuleNotFoundError:\n"
               "    print('missing')\nprint('minros' in sys.modules)", tmp_path)
    assert out.stdout.split() == ["missing", "False"], out.stderr


def test_importing_minros_installs_nothing(tmp_path: Path):
    out = _run("import sys\nbefore = list(sys.meta_path)\nimport minros, minros.msgs\n"
               "print(sys.meta_path == before)", tmp_path)
    assert out.stdout.strip() == "True", out.stderr


def test_a_real_python_package_wins_over_a_ros_package_of_its_name(tmp_path: Path):
    _package(tmp_path / "ws", "json")  # a ROS package named as a module of the standard library
    out = _run("import json\nprint(json.dumps([1]))", tmp_path, ROS_PACKAGE_PATH=str(tmp_path / "ws"))
    assert out.stdout.strip() == "[1]", out.stderr
    assert sys.executable  # the venv's interpreter ran both sides
