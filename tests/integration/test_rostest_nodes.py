"""rostest's own test nodes (hztest, paramtest, publishtest, advertisetest) in a .test file
run by minros's rostest, as a package's tests use them; and rostest's master has no rosout.

Each check is there twice where it can fail: once it should pass and once it should not, so a
node that always passes (or always fails) is caught.
"""

from __future__ import annotations

import subprocess
import xml.etree.ElementTree as ET

import pytest

from support import PYTHON, ros_env

TEST_FILE = """<launch>
  <param name="answer" value="42"/>
  <node name="pub" pkg="rostopic" type="rostopic" args="pub -r 10 chatter std_msgs/String hello"/>
  <node name="adder" pkg="rospy_tutorials" type="add_two_ints_server"/>

  <test test-name="hz_right" pkg="rostest" type="hztest">
    <param name="topic" value="chatter"/> <param name="hz" value="10.0"/>
    <param name="hzerror" value="3.0"/> <param name="test_duration" value="2.0"/>
  </test>
  <test test-name="hz_wrong" pkg="rostest" type="hztest">
    <param name="topic" value="chatter"/> <param name="hz" value="50.0"/>
    <param name="hzerror" value="5.0"/> <param name="test_duration" value="1.0"/>
  </test>
  <test test-name="hz_silent" pkg="rostest" type="hztest">
    <param name="topic" value="nobody_publishes"/> <param name="hz" value="0"/>
    <param name="test_duration" value="0.5"/> <param name="wait_time" value="1.0"/>
  </test>
  <test test-name="hz_unset" pkg="rostest" type="hztest"/>
  <test test-name="param_right" pkg="rostest" type="paramtest">
    <param name="param_name_target" value="/answer"/> <param name="param_value_expected" value="42"/>
  </test>
  <test test-name="param_wrong" pkg="rostest" type="paramtest">
    <param name="param_name_target" value="/answer"/> <param name="param_value_expected" value="41"/>
  </test>
  <test test-name="publish" pkg="rostest" type="publishtest">
    <rosparam>
      topics:
        - name: /chatter
          timeout: 10
        - name: /nobody_publishes
          timeout: 1
          negative: true
    </rosparam>
  </test>
  <test test-name="publish_missing" pkg="rostest" type="publishtest">
    <rosparam>
      topics: [{name: /nobody_publishes, timeout: 1}]
    </rosparam>
  </test>
  <test test-name="advertise" pkg="rostest" type="advertisetest">
    <rosparam>
      topics:
        - {name: /chatter, timeout: 10, type: std_msgs/String}
        - {name: /nobody_publishes, timeout: 1, negative: true}
      services:
        - {name: /add_two_ints, timeout: 10, type: rospy_tutorials/AddTwoInts}
    </rosparam>
  </test>
  <test test-name="advertise_wrong_type" pkg="rostest" type="advertisetest">
    <rosparam>
      topics: [{name: /chatter, timeout: 10, type: std_msgs/Int32}]
    </rosparam>
  </test>
  <test test-name="no_rosout" pkg="rostest_nodes_pkg" type="check_no_rosout.py"/>
</launch>
"""

#: as ROS's rostest: the test's master is its own and runs no core node, so /rosout is free
CHECK_NO_ROSOUT = """#!/usr/bin/env python
import sys
import unittest

import rospy
import rostest


class NoRosout(unittest.TestCase):
    def test_master_has_no_rosout_node(self):
        with self.assertRaises(Exception):
            rostest.get_master().lookupNode('/rosout')


rospy.init_node('check_no_rosout')
rostest.rosrun('rostest_nodes_pkg', 'no_rosout', NoRosout, sys.argv)
"""


@pytest.fixture(scope="module")
def outcome(tmp_path_factory) -> dict:
    root = tmp_path_factory.mktemp("rostest_nodes")
    pkg = root / "src" / "rostest_nodes_pkg"
    (pkg / "test").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package format='2'><name>rostest_nodes_pkg</name>"
                                     "<version>0.0.1</version></package>\n")
    (pkg / "test" / "nodes.test").write_text(TEST_FILE)
    script = pkg / "test" / "check_no_rosout.py"
    script.write_text(CHECK_NO_ROSOUT)
    script.chmod(0o755)
    home = root / "home"
    env = ros_env(None, home, {"ROS_PACKAGE_PATH": str(root / "src")})
    env.pop("ROS_MASTER_URI", None)
    proc = subprocess.run([PYTHON, "-m", "minros", "test", "rostest_nodes_pkg", "nodes.test"],
                          env=env, capture_output=True, text=True, timeout=240)
    results = home / "test_results" / "rostest_nodes_pkg"
    cases = {}
    for path in results.glob("rosunit-*.xml"):
        name = path.stem.removeprefix("rosunit-")
        cases[name] = {c.get("name"): not any(ch.tag in ("failure", "error") for ch in c)
                       for c in ET.parse(path).getroot().iter("testcase")}
    return {"proc": proc, "cases": cases}


def _passed(outcome: dict, test: str, case: str) -> bool:
    cases = outcome["cases"]
    assert test in cases, (f"no results of {test}: " + outcome["proc"].stdout[-3000:]
                           + outcome["proc"].stderr[-3000:])
    assert case in cases[test], cases[test]
    return cases[test][case]


def test_hztest_measures_the_rate(outcome):
    assert _passed(outcome, "hz_right", "test_hz")
    assert not _passed(outcome, "hz_wrong", "test_hz")


def test_hztest_with_hz_zero_wants_silence(outcome):
    assert _passed(outcome, "hz_silent", "test_hz")


def test_hztest_without_its_parameters_fails(outcome):
    assert not _passed(outcome, "hz_unset", "test_hz")


def test_paramtest_compares_the_value(outcome):
    assert _passed(outcome, "param_right", "test_param")
    assert not _passed(outcome, "param_wrong", "test_param")


def test_publishtest(outcome):
    assert _passed(outcome, "publish", "test_publish")
    assert not _passed(outcome, "publish_missing", "test_publish")


def test_advertisetest_checks_names_and_types(outcome):
    assert _passed(outcome, "advertise", "test_advertise_topics")
    assert _passed(outcome, "advertise", "test_advertise_services")
    assert not _passed(outcome, "advertise_wrong_type", "test_advertise_topics")


def test_rostest_starts_no_rosout(outcome):
    assert _passed(outcome, "no_rosout", "test_master_has_no_rosout_node")


def test_the_summary_counts_every_case(outcome):
    proc = outcome["proc"]
    assert proc.returncode == 2, proc.stdout + proc.stderr  # checks failed, as intended
    assert " * TESTS: 13\n" in proc.stdout, proc.stdout
