#!/usr/bin/env python3
"""Run ROS's own Python unit suites against minros and against Debian's ROS 1; print both counts.

    .venv/bin/python scripts/upstream_suites.py --ros-comm DIR --genpy DIR --genmsg DIR \\
        [--geometry DIR] [--diagnostics DIR] [--urdf-parser-py DIR] [--vision-opencv DIR] \\
        [--only SUITE ...] \\
        [--side minros|debian|both] [--diff] [--keep DIR]

Each DIR is a checkout of the public repository (ros/ros_comm, ros/genpy, ros/genmsg,
ros/geometry, ros/diagnostics, ros/urdf_parser_py; the fetch tool or git clone gives one; the
tags of Debian's versions are 1.15.15, 0.6.16, 0.6.0, 1.13.2 and 1.11.0; urdf_parser_py, which
Debian lacks, at noetic's 0.4.6; ros-perception/vision_opencv, whose cv_bridge tests Debian's
source package ros-vision-opencv 1.16.2 carries too: ``bash scripts/install-ros-reference.sh
--sources DIR ros-vision-opencv`` unpacks it). The tests are run where they are, unedited;
nothing of them is copied into this repository. A suite whose checkout is not given is left out.

The integration tests (rostest, live master) are scripts/rostest_suites.py's.

Both sides run the same files through pytest, each in a fresh process:
- minros: this interpreter (the venv), whose rospy, genpy, roslib, ... are minros's. The test
  packages' messages (test_rospy, test_roslib_comm, ...) come from minros's import hook, with
  the checkout's package folders on ROS_PACKAGE_PATH.
- Debian: /usr/bin/python3's packages, through a venv with --system-site-packages that adds
  pytest only (Debian's interpreter has none; --debian-python names another). The test
  packages' messages are generated first by Debian's own genpy into a scratch folder.
Both get a two-line ``nose.tools`` (``nottest``), which genpy's test_genpy_message imports.
A library Debian lacks (urdf_parser_py) is upstream's own code from the checkout on the Debian
side; on the minros side minros's package is put ahead of the checkout's copy, which the tests
add to sys.path themselves.

The table counts passed tests per suite (pytest's junit report: tests - failures - errors -
skipped); ``--diff`` lists the tests Debian passes and minros does not, and the reverse.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

#: The interpreter that sees Debian's ROS 1.
SYSTEM_PYTHON = "/usr/bin/python3"
DEFAULT_DEBIAN_VENV = Path.home() / ".cache" / "minros" / "upstream-debian-venv"
SUITE_TIMEOUT = 900  # seconds for one suite on one side; a hang fails that suite, not the run


@dataclass
class Suite:
    """One upstream suite: test files of one checkout, and the message packages they import."""

    name: str
    repo: str  # key of the checkout: ros_comm, genpy, genmsg, geometry, diagnostics
    paths: Sequence[str]  # test files or folders, relative to the checkout
    #: (package, folder holding its msg/ and srv/, relative) for the test messages the tests
    #: import, which catkin would generate when building the tests
    messages: Sequence[Tuple[str, str]] = ()
    target: bool = True  # counted in the targets; other suites are informational
    note: str = ""
    #: packages the tests find in the checkout itself (test_urdf.py appends ../src to sys.path):
    #: the minros side gets minros's own ahead of them on PYTHONPATH
    shadowed: Sequence[str] = ()
    #: folders of the checkout on the Debian side's PYTHONPATH: a library Debian has no package
    #: of, run as upstream's own code
    debian_pythonpath: Sequence[str] = ()


SUITES: List[Suite] = [
    Suite("rospy-unit", "ros_comm", ["test/test_rospy/test/unit"],
          [("test_rospy", "test/test_rospy"), ("test_rosmaster", "test/test_rosmaster")]),
    Suite("roslib_comm", "ros_comm", ["test/test_roslib_comm/test"],
          [("test_roslib_comm", "test/test_roslib_comm")]),
    # genpy's test/msg/generate_test_messages.py generates these into the genpy package
    Suite("genpy", "genpy", ["test"], [("genpy", "test")]),
    Suite("genmsg", "genmsg", ["test"]),
    Suite("message_filters", "ros_comm", ["utilities/message_filters/test/test_approxsync.py",
                                          "utilities/message_filters/test/test_message_filters_cache.py"]),
    Suite("tf-testPython", "geometry", ["tf/test/testPython.py"]),
    Suite("diagnostic_updater", "diagnostics",
          ["diagnostic_updater/test/test_DiagnosticStatusWrapper.py",
           "diagnostic_updater/test/diagnostic_updater_test.py"]),
    Suite("test_rosbag", "ros_comm", ["test/test_rosbag/test/test_bag.py"]),
    # beyond the targets: the other catkin_add_nosetests suites of ros_comm
    Suite("rosgraph", "ros_comm", ["tools/rosgraph/test"], target=False),
    Suite("rosmaster", "ros_comm", ["tools/rosmaster/test"], target=False),
    Suite("roslaunch-unit", "ros_comm", ["tools/roslaunch/test/unit"], target=False),
    Suite("roswtf", "ros_comm", ["utilities/roswtf/test"], target=False),
    Suite("rosbag-roundtrip", "ros_comm", ["tools/rosbag/test"], target=False),
    # the command-line tools' nosetests (their offline parts; the online ones need a graph)
    Suite("test_rosparam", "ros_comm", ["test/test_rosparam/test"], target=False),
    Suite("test_rostopic", "ros_comm", ["test/test_rostopic/test"],
          [("test_rostopic", "test/test_rostopic")], target=False),
    Suite("test_rosservice", "ros_comm", ["test/test_rosservice/test"],
          [("test_rosservice", "test/test_rosservice")], target=False),
    Suite("rosmsg", "ros_comm", ["tools/rosmsg/test"], target=False),
    Suite("rostopic-offline", "ros_comm", ["tools/rostopic/test/test_rostopic_command_line_offline.py"],
          target=False),
    Suite("topic_tools-args", "ros_comm", ["tools/topic_tools/test/args.py"], target=False),
    # a library Debian lacks: its "Debian" column is upstream's own code under Debian's Python
    Suite("urdf_parser_py", "urdf_parser_py", ["test"], target=False,
          shadowed=["urdf_parser_py"], debian_pythonpath=["src"]),
    # cv_bridge's Python tests (its C++ tests need a build)
    Suite("cv_bridge", "vision_opencv", ["cv_bridge/test/enumerants.py",
                                         "cv_bridge/test/conversions.py",
                                         "cv_bridge/test/python_bindings.py"], target=False),
]

#: Test-only modules the upstream tests import that neither side installs, on both sides'
#: PYTHONPATH: nose's assert_* names (unittest's, spelt as nose spells them) and ``mock``
#: (Python's unittest.mock, which the mock package on PyPI backports).
SHIMS = {
    "nose/__init__.py": '"""nose stand-in for upstream tests: only what they import."""\n',
    "nose/tools.py": (
        "import re\nimport unittest\n\n\n"
        "def nottest(func):\n    func.__test__ = False\n    return func\n\n\n"
        "def istest(func):\n    func.__test__ = True\n    return func\n\n\n"
        "class _Case(unittest.TestCase):\n    def runTest(self):\n        pass\n\n\n"
        "_case = _Case()\n"
        "for _name in dir(_case):\n"
        "    if _name.startswith('assert') and '_' not in _name:\n"
        "        globals()[re.sub('([A-Z])', lambda m: '_' + m.group(1).lower(), _name)] = "
        "getattr(_case, _name)\n"
        "assert_regexp_matches = _case.assertRegex\n"),
    "mock/__init__.py": "from unittest.mock import *  # noqa\nfrom unittest.mock import patch  # noqa\n",
}

#: Generates one message package's Python modules with Debian's genpy, as catkin would. A
#: package that is also a Python package (genpy itself) gets catkin's devel-space __init__:
#: the installed package's folder joins __path__ and its __init__ runs.
GENERATE = r"""
import glob, importlib.util, os, sys
from genpy.generator import MsgGenerator, SrvGenerator
from genpy.generate_initpy import write_modules
pkg, pkg_dir, out = sys.argv[1:4]
search = {pkg: [os.path.join(pkg_dir, 'msg')]}
for spec in sys.argv[4:]:
    name, path = spec.split(':', 1)
    search.setdefault(name, []).append(path)
for share in glob.glob('/usr/share/*/msg'):
    search.setdefault(os.path.basename(os.path.dirname(share)), []).append(share)
for kind, gen in (('msg', MsgGenerator()), ('srv', SrvGenerator())):
    files = sorted(glob.glob(os.path.join(pkg_dir, kind, '*.' + kind)))
    if files:
        dest = os.path.join(out, pkg, kind)
        if gen.generate_messages(pkg, files, dest, search):
            sys.exit('genpy failed on ' + pkg + '/' + kind)
        write_modules(dest)
installed = importlib.util.find_spec(pkg)
with open(os.path.join(out, pkg, '__init__.py'), 'w') as init:
    if installed is not None and installed.submodule_search_locations:
        where = list(installed.submodule_search_locations)[0]
        init.write('__path__.append(%r)\n' % where)
        init.write('exec(compile(open(%r).read(), %r, "exec"))\n'
                   % ((os.path.join(where, '__init__.py'),) * 2))
"""

PACKAGE_XML = """<?xml version="1.0"?>
<package format="2">
  <name>{name}</name>
  <version>0.0.0</version>
  <description>{name}'s test messages (upstream_suites.py)</description>
  <maintainer email="none@example.com">none</maintainer>
  <license>BSD</license>
</package>
"""


def run_pytest(python: str, suite: Suite, root: Path, env: Dict[str, str], scratch: Path,
               label: str) -> Tuple[Optional[Dict[str, str]], str]:
    """Run one suite; the outcome of every test (``passed``/``failed``/``skipped``) by id."""
    report = scratch / f"{suite.name}-{label}.xml"
    ini = scratch / "pytest.ini"  # empty: an upstream setup.cfg must not configure the run
    ini.write_text("[pytest]\n")
    argv = [python, "-m", "pytest", "-p", "no:cacheprovider", "-c", str(ini),
            "--rootdir", str(root), "-q", "--timeout", "120", f"--junitxml={report}",
            "-o", "junit_family=xunit1", "--continue-on-collection-errors", *[str(root / p) for p in suite.paths]]
    try:
        # not in the checkout: python -m puts the working folder first on sys.path, where a
        # checkout folder (geometry/tf) would shadow the package under test
        proc = subprocess.run(argv, cwd=scratch, env=env, capture_output=True, text=True,
                              timeout=SUITE_TIMEOUT)
        output = proc.stdout + proc.stderr
    except subprocess.TimeoutExpired as exc:
        return None, f"timed out after {SUITE_TIMEOUT} s\n{exc.stdout or ''}"
    if not report.exists():
        return None, output
    outcomes: Dict[str, str] = {}
    for case in ET.parse(report).getroot().iter("testcase"):
        test_id = f"{case.get('classname')}::{case.get('name')}"
        kinds = {child.tag for child in case}
        if kinds & {"failure", "error"}:
            outcomes[test_id] = "failed"
        elif "skipped" in kinds:
            outcomes[test_id] = "skipped"
        else:
            outcomes[test_id] = "passed"
    return outcomes, output


def base_env(scratch: Path, pythonpath: Sequence[Path], package_path: Sequence[Path]) -> Dict[str, str]:
    """The environment of a catkin workspace's tests: its source space on ROS_PACKAGE_PATH."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("ROS_") and k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    home = scratch / "ros_home"
    env.update({
        "ROS_HOME": str(home), "ROS_LOG_DIR": str(home / "log"), "ROS_ROOT": str(scratch / "ros"),
        "ROS_MASTER_URI": "http://localhost:11311", "ROS_HOSTNAME": "localhost",
        "ROS_PACKAGE_PATH": os.pathsep.join(str(p) for p in package_path),
        "PYTHONPATH": os.pathsep.join(str(p) for p in pythonpath),
        "PYTHONDONTWRITEBYTECODE": "1",
    })
    return env


#: For minros, what catkin_make does for a package's messages: a stub package (two lines per
#: module) in the devel space, so ``import <pkg>.msg`` works before anything imported minros.
#: A package that is a Python package already (genpy) is left to minros's import hook.
WRITE_STUBS = r"""
import importlib.util, sys
existing = [n for n in sys.argv[2:] if importlib.util.find_spec(n) is not None]
from minros.msgs.importer import write_stub_package
for name in sys.argv[2:]:
    if name not in existing:
        write_stub_package(name, sys.argv[1])
"""


def message_overlays(suite: Suite, root: Path, out: Path) -> None:
    """For minros: a package folder per test message set that is not a package folder already
    (genpy's test/msg), so minros's import hook serves ``<pkg>.msg`` from the checkout."""
    for name, rel in suite.messages:
        src = root / rel
        if (src / "package.xml").exists():
            continue
        pkg = out / name
        pkg.mkdir(parents=True, exist_ok=True)
        (pkg / "package.xml").write_text(PACKAGE_XML.format(name=name))
        for kind in ("msg", "srv"):
            if (src / kind).is_dir() and not (pkg / kind).exists():
                (pkg / kind).symlink_to(src / kind)


#: For minros: the folder holding minros's own copy of each named package (a link to it, so
#: nothing else of that folder comes first).
SHADOW = r"""
import importlib.util, os, sys
out = sys.argv[1]
for name in sys.argv[2:]:
    spec = importlib.util.find_spec(name)
    if spec is None or not spec.submodule_search_locations:
        sys.exit(name + ': not a package of this interpreter')
    link = os.path.join(out, name)
    if not os.path.lexists(link):
        os.symlink(list(spec.submodule_search_locations)[0], link)
"""


def debian_python(path: Optional[str]) -> str:
    """An interpreter that sees Debian's packages and has pytest (a venv made once if needed)."""
    if path:
        return path
    python = DEFAULT_DEBIAN_VENV / "bin" / "python"
    if not python.exists():
        print(f"making {DEFAULT_DEBIAN_VENV} (Debian's packages + pytest) ...", file=sys.stderr)
        subprocess.run([SYSTEM_PYTHON, "-m", "venv", "--system-site-packages",
                        str(DEFAULT_DEBIAN_VENV)], check=True)
        subprocess.run([str(python), "-m", "pip", "install", "-q", "pytest", "pytest-timeout"],
                       check=True)
    return str(python)


def generate_debian_messages(python: str, suite: Suite, root: Path, out: Path) -> None:
    """The suite's test message packages generated by Debian's genpy into ``out``."""
    deps = [f"{name}:{root / rel / 'msg'}" for name, rel in suite.messages]
    for name, rel in suite.messages:
        if (out / name).exists():
            continue
        proc = subprocess.run([python, "-c", GENERATE, name, str(root / rel), str(out), *deps],
                              capture_output=True, text=True, timeout=300)
        if proc.returncode:
            raise SystemExit(f"generating {name} with Debian's genpy failed:\n"
                             f"{proc.stdout}{proc.stderr}")


def count(outcomes: Optional[Dict[str, str]]) -> str:
    if outcomes is None:
        return "error"
    passed = sum(1 for v in outcomes.values() if v == "passed")
    return f"{passed}/{len(outcomes)}"


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    for repo in ("ros-comm", "genpy", "genmsg", "geometry", "diagnostics", "urdf-parser-py",
                 "vision-opencv"):
        parser.add_argument(f"--{repo}", metavar="DIR", type=Path,
                            help=f"checkout of ros/{repo.replace('-', '_')}")
    parser.add_argument("--only", nargs="+", metavar="SUITE",
                        help="run only these suites: " + ", ".join(s.name for s in SUITES))
    parser.add_argument("--side", choices=("minros", "debian", "both"), default="both")
    parser.add_argument("--minros-python", default=sys.executable,
                        help="interpreter with minros installed (default: this one)")
    parser.add_argument("--debian-python",
                        help=f"interpreter seeing Debian's ROS with pytest (default: a venv in "
                             f"{DEFAULT_DEBIAN_VENV}, made on first use)")
    parser.add_argument("--diff", action="store_true",
                        help="list the tests whose outcome differs between the two sides")
    parser.add_argument("--keep", type=Path, metavar="DIR",
                        help="keep the junit reports and pytest output in DIR")
    parser.add_argument("--output", action="store_true",
                        help="print pytest's output of a side that did not report")
    args = parser.parse_args(argv)

    roots = {"ros_comm": args.ros_comm, "genpy": args.genpy, "genmsg": args.genmsg,
             "geometry": args.geometry, "diagnostics": args.diagnostics,
             "urdf_parser_py": args.urdf_parser_py, "vision_opencv": args.vision_opencv}
    for key, root in roots.items():
        if root is not None and not root.is_dir():
            parser.error(f"--{key.replace('_', '-')} {root}: no such folder")
    suites = [s for s in SUITES if roots[s.repo] is not None and (not args.only or s.name in args.only)]
    if args.only:
        unknown = set(args.only) - {s.name for s in SUITES}
        if unknown:
            parser.error(f"unknown suite(s): {', '.join(sorted(unknown))}")
    if not suites:
        parser.error("no suite to run: give at least one checkout (--ros-comm, --genpy, ...)")

    sides = ["minros", "debian"] if args.side == "both" else [args.side]
    deb_python = debian_python(args.debian_python) if "debian" in sides else ""
    scratch = Path(tempfile.mkdtemp(prefix="upstream-suites-"))
    try:
        shim = scratch / "shim"
        for rel, text in SHIMS.items():
            (shim / rel).parent.mkdir(parents=True, exist_ok=True)
            (shim / rel).write_text(text)
        generated = scratch / "debian-gen"
        overlays = scratch / "minros-packages"
        devel = scratch / "minros-devel"
        shadows = scratch / "minros-first"
        shadows.mkdir()
        rows = []
        for suite in suites:
            root = roots[suite.repo].resolve()
            results: Dict[str, Optional[Dict[str, str]]] = {}
            for side in sides:
                if side == "minros":
                    message_overlays(suite, root, overlays)
                    env = base_env(scratch, [shadows, shim, devel], [overlays, root])
                    python = args.minros_python
                    if suite.shadowed:
                        subprocess.run([python, "-c", SHADOW, str(shadows), *suite.shadowed],
                                       env=env, check=True, timeout=120)
                    if suite.messages:
                        subprocess.run([python, "-c", WRITE_STUBS, str(devel),
                                        *[name for name, _ in suite.messages]],
                                       env=env, check=True, timeout=120)
                else:
                    generate_debian_messages(deb_python, suite, root, generated)
                    env = base_env(scratch, [shim, generated, *[root / p for p in suite.debian_pythonpath]],
                                   [root, Path("/usr/share")])
                    python = deb_python
                print(f"{suite.name}: {side} ...", file=sys.stderr, flush=True)
                outcomes, output = run_pytest(python, suite, root, env, scratch, side)
                results[side] = outcomes
                if args.keep:
                    args.keep.mkdir(parents=True, exist_ok=True)
                    (args.keep / f"{suite.name}-{side}.txt").write_text(output)
                    report = scratch / f"{suite.name}-{side}.xml"
                    if report.exists():
                        shutil.copy(report, args.keep / report.name)
                if outcomes is None and args.output:
                    print(output[-4000:], file=sys.stderr)
            rows.append((suite, results))

        print(f"\n{'suite':<22}{'minros':>12}{'Debian':>12}")
        totals = {side: [0, 0] for side in sides}
        for suite, results in rows:
            cells = [count(results[s]) if s in results else "-" for s in ("minros", "debian")]
            mark = "" if suite.target else "   (not a target)"
            print(f"{suite.name:<22}{cells[0]:>12}{cells[1]:>12}{mark}")
            if suite.name in ("rospy-unit", "roslib_comm", "genpy", "genmsg"):
                for side in sides:
                    outcomes = results[side] or {}
                    totals[side][0] += sum(1 for v in outcomes.values() if v == "passed")
                    totals[side][1] += len(outcomes)
        if any(s.name in ("rospy-unit", "roslib_comm", "genpy", "genmsg") for s, _ in rows):
            cells = [f"{totals[s][0]}/{totals[s][1]}" if s in totals else "-"
                     for s in ("minros", "debian")]
            print(f"{'rospy+roslib+gen*':<22}{cells[0]:>12}{cells[1]:>12}")
        if args.diff and len(sides) == 2:
            for suite, results in rows:
                mine, theirs = results["minros"] or {}, results["debian"] or {}
                lost = sorted(t for t, v in theirs.items() if v == "passed" and mine.get(t) != "passed")
                won = sorted(t for t, v in mine.items() if v == "passed" and theirs.get(t) != "passed")
                for title, tests in (("Debian passes, minros does not", lost),
                                     ("minros passes, Debian does not", won)):
                    if tests:
                        print(f"\n{suite.name}: {title}:")
                        for test in tests:
                            print(f"  {test}")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
