"""rosunit.junitxml and XMLTestRunner (minros.tools.junitxml) against Debian's rosunit: each
reads the other's JUnit files to the same counts and cases."""

from __future__ import annotations

import json
import subprocess
import unittest
from pathlib import Path

import pytest

import rosunit.core
import rosunit.junitxml
from support import REFERENCE_PYTHON, reference_env, reference_imports, require_reference

pytestmark = pytest.mark.interop


class Sample(unittest.TestCase):
    __test__ = False  # run by the test below, not collected by pytest

    def test_passes(self):
        self.assertTrue(True)

    def test_fails(self):
        self.assertEqual(1, 2, "one is not two <&>")

    def test_errors(self):
        raise RuntimeError("boom \x01")


DEBIAN = r'''
import json, sys, unittest
import rosunit.junitxml as j
from rosunit.xmlrunner import XMLTestRunner
class Sample(unittest.TestCase):
    __test__ = False  # run by the test below, not collected by pytest

    def test_passes(self): pass
    def test_fails(self): self.assertEqual(1, 2)
with open(sys.argv[2], "w") as out:
    XMLTestRunner(stream=out).run(unittest.TestLoader().loadTestsFromTestCase(Sample))
r = j.read(sys.argv[1], "sample")
print(json.dumps([r.num_tests, r.num_errors, r.num_failures,
                  sorted((c.name.rsplit("/", 1)[-1], c.passed) for c in r.test_case_results)]))
'''


def test_each_side_reads_the_others_files(tmp_path: Path):
    require_reference()
    if not reference_imports("rosunit.junitxml"):
        pytest.skip("Debian's python3-rosunit is not installed")
    ours = tmp_path / "ours.xml"
    rosunit.core.create_xml_runner("pkg", "sample", results_file=str(ours)).run(
        unittest.TestLoader().loadTestsFromTestCase(Sample))
    theirs = tmp_path / "theirs.xml"
    out = subprocess.run([REFERENCE_PYTHON, "-c", DEBIAN, str(ours), str(theirs)],
                         capture_output=True, text=True, env=reference_env({}), timeout=60)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout.strip().splitlines()[-1]) == [3, 1, 1, [["test_errors", False], ["test_fails", False],
                                                ["test_passes", True]]]
    mine = rosunit.junitxml.read(str(theirs), "theirs")
    assert (mine.num_tests, mine.num_errors, mine.num_failures) == (2, 0, 1)
    assert sorted((c.name, c.passed) for c in mine.test_case_results) == \
        [("test_fails", False), ("test_passes", True)]


def test_unreadable_file_counts_as_one_error(tmp_path: Path):
    bad = tmp_path / "bad.xml"
    bad.write_text("<testsuite")
    result = rosunit.junitxml.read(str(bad), "bad")
    assert (result.num_tests, result.num_errors) == (1, 1)
    assert "cannot read test results" in result.test_case_results[0].errors[0].text
