"""rostest: a .test file of rospy nodes checked by unittest test nodes, run by minros's rostest
(a master of its own on a free port, the file's nodes and parameters, JUnit results)."""

from __future__ import annotations

import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from support import PYTHON, ros_env

PKGS = Path(__file__).resolve().parent / "rostest_pkgs"


def _rostest(home: Path, *args: str, timeout: float = 90) -> subprocess.CompletedProcess:
    env = ros_env(None, home, {"ROS_PACKAGE_PATH": str(PKGS)})
    env.pop("ROS_MASTER_URI", None)
    return subprocess.run([PYTHON, "-m", "minros", "test", *args], env=env, capture_output=True,
                          text=True, timeout=timeout)


def _suite(path: Path) -> ET.Element:
    root = ET.parse(path).getroot()
    assert root.tag == "testsuite"
    return root


def test_rostest_runs_rospy_nodes_and_unittest_checks(ros_home: Path) -> None:
    out = _rostest(ros_home, "rostest_demo", "counter.test")
    assert out.returncode == 0, out.stdout + out.stderr
    results = ros_home / "test_results" / "rostest_demo"
    # what ROS's rostest prints (the launch's own messages go to the log file)
    log = next((ros_home / "log").glob("rostest-*.log"))
    assert out.stdout == (
        f"... logging to {log}\n"
        f"[ROSUNIT] Outputting test results to {results / 'rostest-test_counter.xml'}\n"
        "[Testcase: testtest_counter] ... ok\n\n"
        "[ROSTEST]" + "-" * 71 + "\n\n"
        "[rostest_demo.rosunit-test_counter/test_counts_up_from_start][passed]\n"
        "[rostest_demo.rosunit-test_counter/test_graph][passed]\n"
        "[rostest_demo.rosunit-test_counter/test_parameter_from_launch_file][passed]\n\n"
        "SUMMARY\n\033[32m * RESULT: SUCCESS\033[0m\n * TESTS: 3\n * ERRORS: 0\n * FAILURES: 0\n\n"
        f"rostest log file is in {log}\n")
    assert "process[counter-1]: started with pid" in log.read_text()
    results = ros_home / "test_results" / "rostest_demo"
    node = _suite(results / "rosunit-test_counter.xml")
    assert (node.get("tests"), node.get("failures"), node.get("errors")) == ("3", "0", "0")
    assert sorted(c.get("name") for c in node.iter("testcase")) == [
        "test_counts_up_from_start", "test_graph", "test_parameter_from_launch_file"]
    whole = _suite(results / "rostest-test_counter.xml")
    assert [c.get("name") for c in whole.iter("testcase")] == ["testtest_counter"]


def test_rostest_by_path_reports_a_failing_check(ros_home: Path) -> None:
    out = _rostest(ros_home, str(PKGS / "rostest_demo" / "test" / "fails.test"))
    assert out.returncode == 2, out.stdout + out.stderr  # rostest's status for failed checks
    assert "\033[1;31m * RESULT: FAIL\033[0m\n" in out.stdout
    head = "[rostest_demo.rosunit-test_fails/test_wrong][FAILURE]"
    assert f"\n{head}{'-' * (80 - len(head))}\nTraceback" in out.stdout
    assert "AssertionError: 42 != 41\n" + "-" * 80 + "\n" in out.stdout
    node = _suite(ros_home / "test_results" / "rostest_demo" / "rosunit-test_fails.xml")
    assert node.get("failures") == "1"
    failure = next(node.iter("failure"))
    assert "41" in failure.text and "42" in failure.text


@pytest.mark.smoke
def test_text_mode_prints_the_cases(ros_home: Path) -> None:
    out = _rostest(ros_home, "--text", "rostest_demo", "counter.test")
    assert out.returncode == 0, out.stdout + out.stderr
    assert "test_graph (__main__.TestCounter" in out.stderr + out.stdout
    # as ROS's: no summary, which the cases printed as text cannot give
    assert "WARNING: overall test result is not accurate when --text is enabled\n" in out.stdout
    assert "SUMMARY" not in out.stdout


def test_broken_test_entry_is_one_clear_error(ros_home: Path) -> None:
    out = _rostest(ros_home, "rostest_demo", "broken.test")
    assert out.returncode == 1
    assert out.stdout == f"... logging to {next((ros_home / 'log').glob('rostest-*.log'))}\n"
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert "broken.test:2: <test> tag is missing required attribute 'test-name'" in lines[0]
    assert "Traceback" not in out.stderr


def test_a_test_that_writes_no_results_fails(ros_home: Path, tmp_path: Path) -> None:
    test_file = tmp_path / "silent.test"
    test_file.write_text('<launch><test test-name="silent" pkg="rostest_demo" type="counter.py" '
                         'time-limit="2"/></launch>')
    out = _rostest(ros_home, str(test_file))
    assert out.returncode == 1  # rostest's status for a test that did not run properly
    assert "test [silent] timed out after 2 s" in out.stderr
    assert ("[Testcase: testsilent] ... FAILURE!\nFAILURE: test [silent] timed out after 2 s\n"
            + "-" * 80 + "\n") in out.stdout
    assert "[testsilent][failed]\n" in out.stdout
    assert "\033[1;31m * FAILURES: 1\033[0m" in out.stdout
    assert out.stdout.endswith(" * testsilent\n\nrostest log file is in "
                               f"{next((ros_home / 'log').glob('rostest-*.log'))}\n")


def test_rostest_runner_api_runs_a_file_as_a_unittest_class(ros_home: Path) -> None:
    """rostest.runner.createUnitTest: a test<name> method per <test>, run under a
    ROSTestLaunchParent (a master of its own); a missing test node fails its method."""
    broken = ros_home / "missing.test"
    broken.write_text('<launch><test test-name="nope" pkg="rostest_demo" type="nope.py"/>'
                      "</launch>")
    code = f'''
import unittest, rostest.runner as r
for f in [{str(PKGS / "rostest_demo" / "test" / "counter.test")!r}, {str(broken)!r}]:
    case = r.createUnitTest("rostest_demo", f)
    res = unittest.TextTestRunner(verbosity=0).run(unittest.TestLoader().loadTestsFromTestCase(case))
    print("RUN", case.__module__, case.__name__, res.testsRun, len(res.failures), len(res.errors))
    for _, tb in res.failures:
        print("FAIL", tb.strip().splitlines()[-1])
g = r.getResults()
print("TOTAL", g.num_tests, g.num_errors, g.num_failures, len(r.getRostestParents()))
'''
    env = ros_env(None, ros_home, {"ROS_PACKAGE_PATH": str(PKGS)})
    env.pop("ROS_MASTER_URI", None)
    out = subprocess.run([PYTHON, "-c", code], env=env, capture_output=True, text=True,
                         timeout=90)
    assert out.returncode == 0, out.stdout + out.stderr
    lines = [line for line in out.stdout.splitlines() if line.startswith(("RUN", "FAIL", "TOTAL"))]
    assert lines == [
        "RUN rostest.runner RosTest 1 0 0",
        "RUN rostest.runner RosTest 1 1 0",
        "FAIL AssertionError: Test node [rostest_demo/nope.py] does not exist or is not executable",
        "TOTAL 3 0 0 2",  # setUp ran for each method, the failing one too
    ]
    assert "[ROSTEST]test [test_counter] results summary: 0 errors, 0 failures, 3 tests" in out.stdout
    node = _suite(ros_home / "test_results" / "rostest_demo" / "rosunit-test_counter.xml")
    assert node.get("tests") == "3"


def test_rosunit_runs_a_test_program_and_writes_junit(ros_home: Path) -> None:
    """``rosunit FILE``: the program runs with --gtest_output, its results and the wrapper's
    are written as JUnit, and the status says whether its checks passed."""
    env = ros_env(None, ros_home, {"ROS_PACKAGE_PATH": str(PKGS)})
    scripts = PKGS / "rostest_demo" / "scripts"
    results = ros_home / "test_results" / "rostest_demo"
    out = subprocess.run([PYTHON, "-m", "minros", "unit", str(scripts / "unit_fails.py")],
                         env=env, capture_output=True, text=True, timeout=60, cwd=ros_home)
    assert out.returncode == 2, out.stdout + out.stderr  # the program's check failed
    assert "[ROSUNIT]test [unit_fails] results summary: 0 errors, 1 failures, 2 tests" in out.stdout
    assert "\033[1;31m * RESULT: FAIL\033[0m\n * TESTS: 2\n" in out.stdout
    node = _suite(results / "rosunit-unit_fails.xml")
    assert (node.get("tests"), node.get("failures")) == ("2", "1")
    wrapper = _suite(results / "rostest-unit_fails.xml")
    assert [c.get("name") for c in wrapper.iter("testcase")] == ["runTest"]
    out = subprocess.run([PYTHON, "-m", "minros", "unit", "--name", "renamed", "--time-limit",
                          "0.5", str(scripts / "unit_fails.py"), "--sleep"], env=env,
                         capture_output=True, text=True, timeout=60, cwd=ros_home)
    assert out.returncode == 1, out.stdout + out.stderr  # the runner's own check: timed out
    assert "\033[1;31m * ERRORS: 1\033[0m\n" in out.stdout
    error = next(_suite(results / "rostest-renamed.xml").iter("error"))
    assert "TestTimeoutException: test max time allotted" in error.text
    out = subprocess.run([PYTHON, "-m", "minros", "unit", "/nowhere/x.py"], env=env,
                         capture_output=True, text=True, timeout=60)
    assert (out.returncode, out.stderr) == (1, "minros unit: error: no such test file: "
                                               "/nowhere/x.py\n")
