"""scripts/surface.py's machinery, without Debian: module names from dpkg paths, exclusions,
and the import worker surviving modules that hang, end the process or print."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("surface", REPO / "scripts" / "surface.py")
surface = importlib.util.module_from_spec(spec)
spec.loader.exec_module(surface)


@pytest.mark.parametrize("path, name", [
    ("/usr/lib/python3/dist-packages/rospy/__init__.py", "rospy"),
    ("/usr/lib/python3/dist-packages/rospy/impl/tcpros.py", "rospy.impl.tcpros"),
    ("/usr/lib/python3/dist-packages/PyKDL.cpython-311-x86_64-linux-gnu.so", "PyKDL"),
    ("/usr/lib/python3/dist-packages/rviz/librviz_sip.so", "rviz.librviz_sip"),
    ("/usr/lib/python3/dist-packages/std_msgs/msg/_String.py", None),
    ("/usr/lib/python3/dist-packages/tf2_py/_tf2.cpython-311-x86_64-linux-gnu.so", None),
    ("/usr/lib/python3/dist-packages/rospy-1.15.15.egg-info/PKG-INFO", None),
    ("/usr/lib/python3/dist-packages/rospy/README.txt", None),
    ("/usr/share/rospy/package.xml", None),
])
def test_module_name(path: str, name) -> None:
    assert surface.module_name(path) == name


def test_exclusions_cover_subpackages_only_when_asked() -> None:
    assert surface.exclusion("rosmake.engine")
    assert surface.exclusion("catkin.builder")
    assert surface.exclusion("catkin.find_in_workspaces") is None  # roslib uses it at run time
    assert surface.exclusion("genmsg.template_tools")  # build-time code writer
    assert surface.exclusion("genmsg.deps") is None  # the rest of genmsg counts
    assert surface.exclusion("rviz")
    assert surface.exclusion("rviz.srv") is None


@pytest.mark.slow
def test_worker_survives_hangs_crashes_and_noise(tmp_path: Path) -> None:
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "hangs.py").write_text("import time\ntime.sleep(60)\n")
    (lib / "dies.py").write_text("import os\nos._exit(3)\n")
    (lib / "noisy.py").write_text(
        'import os, sys\nprint("{\\"done\\": 99}")\nos.write(1, b"junk\\n")\n'
        'sys.stderr.write("more\\n")\nimport json\n\ndef call():\n    pass\n\nVALUE = 3\n')
    (lib / "fine.py").write_text("__all__ = ['a', 'b']\na = b = 1\n")
    jobs = [("hangs", None), ("noisy", None), ("dies", None), ("fine", None), ("absent", None),
            ("fine", ["a", "zz"])]
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    answers = surface.run_imports(sys.executable, jobs, ["noisy", "fine"], 2.0, scratch,
                                  sys_path=[str(lib)])
    assert answers["hangs"]["error"].startswith("timeout")
    assert answers["dies"]["error"] == "the import ended the worker (exit 3)"
    assert answers["noisy"]["names"] == ["VALUE", "call"]  # json (a module) is not counted
    assert answers["absent"]["error"].startswith("ModuleNotFoundError")
    # the last job of a module wins; both answered
    assert answers["fine"] == {"done": 5, "has": ["a"]}
