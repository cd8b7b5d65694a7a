"""scripts/rostest_suites.py's own logic: which .test files a package registers, how a run's
JUnit files are counted (rostest's sum: each <test>'s cases, one failed case for a <test> that
left none), and which files a --check runs again."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

from support import REPO


def _script():
    spec = importlib.util.spec_from_file_location("rostest_suites",
                                                  REPO / "scripts" / "rostest_suites.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["rostest_suites"] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_only_the_registered_tests_count(tmp_path: Path):
    rs = _script()
    pkg = tmp_path / "tools" / "topic_tools"
    pkg.mkdir(parents=True)
    (pkg / "CMakeLists.txt").write_text(
        "if(CATKIN_ENABLE_TESTING)\n  add_rostest(test/relay.test)\n"
        "  #add_rostest(test/relay_latched.test)\n  #rosbuild_add_rostest(test/mux_add.test)\n"
        "  add_rostest( test/drop.test )\n  catkin_add_nosetests(test/args.py)\nendif()\n")
    assert [p.name for p in rs.registered_tests(tmp_path, "tools/topic_tools")] == [
        "relay.test", "drop.test"]


def test_cases_are_counted_as_rostest_sums_them(tmp_path: Path):
    rs = _script()
    results = tmp_path / "results" / "pkg"
    results.mkdir(parents=True)
    (results / "rosunit-talks.xml").write_text(
        '<testsuite tests="2"><testcase classname="__main__.T" name="test_a"/>'
        '<testcase classname="__main__.T" name="test_b"><failure>no</failure></testcase>'
        "</testsuite>")
    (results / "rostest-test_x.xml").write_text(
        '<testsuite tests="2"><testcase classname="rostest.runner.RosTest" name="testtalks"/>'
        '<testcase classname="rostest.runner.RosTest" name="testsilent">'
        "<failure>did not run</failure></testcase></testsuite>")
    cases, not_run = rs.read_cases(tmp_path / "results")
    assert cases == {"rosunit-talks::__main__.T.test_a": True,
                     "rosunit-talks::__main__.T.test_b": False,
                     "silent::<did not run>": False}
    assert not_run == ["silent"]


def test_check_runs_again_the_files_where_minros_is_behind():
    rs = _script()
    a, b = Path("a.test"), Path("b.test")

    def result(test: Path, side: str, passed: int) -> object:
        r = rs.FileResult("suite", test, side)
        r.cases = {f"c{i}": i < passed for i in range(3)}
        return r

    results = [result(a, "minros", 2), result(a, "debian", 3), result(b, "minros", 3),
               result(b, "debian", 1)]
    assert rs.behind(results) == [("suite", a)]
