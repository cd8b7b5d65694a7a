"""rostest: a .test file of rospy nodes checked by unittest test nodes, run by minros's rostest
(a master of its own on a free port, the file's nodes and parameters, JUnit results)."""

from __future__ import annotations

import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

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
    assert " * RESULT: SUCCESS" in out.stdout
    assert " * TESTS: 3" in out.stdout
    results = ros_home / "test_results" / "rostest_demo"
    node = _suite(results / "rosunit-test_counter.xml")
    assert (node.get("tests"), node.get("failures"), node.get("errors")) == ("3", "0", "0")
    assert sorted(c.get("name") for c in node.iter("testcase")) == [
        "test_counts_up_from_start", "test_graph", "test_parameter_from_launch_file"]
    whole = _suite(results / "rostest-test_counter.xml")
    assert [c.get("name") for c in whole.iter("testcase")] == ["testtest_counter"]


def test_rostest_by_path_reports_a_failing_check(ros_home: Path) -> None:
    out = _rostest(ros_home, str(PKGS / "rostest_demo" / "test" / "fails.test"))
    assert out.returncode == 1, out.stdout + out.stderr
    assert " * RESULT: FAIL" in out.stdout
    assert "[__main__.TestFails/test_wrong][FAILURE]" in out.stdout
    node = _suite(ros_home / "test_results" / "rostest_demo" / "rosunit-test_fails.xml")
    assert node.get("failures") == "1"
    failure = next(node.iter("failure"))
    assert "41" in failure.text and "42" in failure.text


def test_text_mode_prints_the_cases(ros_home: Path) -> None:
    out = _rostest(ros_home, "--text", "rostest_demo", "counter.test")
    assert out.returncode == 0, out.stdout + out.stderr
    assert "test_graph (__main__.TestCounter" in out.stderr + out.stdout


def test_broken_test_entry_is_one_clear_error(ros_home: Path) -> None:
    out = _rostest(ros_home, "rostest_demo", "broken.test")
    assert out.returncode == 1
    assert out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr
    assert "broken.test:2: <test> tag is missing required attribute 'test-name'" in lines[0]
    assert "Traceback" not in out.stderr


def test_a_test_that_writes_no_results_fails(ros_home: Path, tmp_path: Path) -> None:
    test_file = tmp_path / "silent.test"
    test_file.write_text('<launch><test test-name="silent" pkg="rostest_demo" type="counter.py" '
                         'time-limit="2"/></launch>')
    out = _rostest(ros_home, str(test_file))
    assert out.returncode == 1
    assert "test [silent] timed out after 2 s" in out.stderr
    assert " * FAILURES: 1" in out.stdout
