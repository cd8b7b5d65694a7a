"""rosunit.junitxml, rosunit.core and rosunit.xmlrunner: JUnit results with rosunit's classes,
over minros's reader and writer (:mod:`minros.tools.testing`).

``read(file, name)`` gives a :class:`Result` with a :class:`TestCaseResult` per case;
``read_all()`` sums every file in the test results folder; ``print_summary`` prints rosunit's
summary block; :class:`XMLTestRunner` runs a unittest suite and writes its JUnit file.
"""

from __future__ import annotations

import os
import re
import sys
import time
import unittest
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Iterable, List, Optional, Sequence

from minros import rosenv
from minros.roslogging import makedirs_with_parent_perms  # noqa: F401 - rosunit.core's too

from . import testing

# ---------------------------------------------------------------------------------------------
# rosunit.junitxml

_INVALID_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def invalid_char_replacer(m: Any) -> str:
    return f"&#x{ord(m.group(0)):04X};"


def filter_nonprintable_text(text: str) -> str:
    """``text`` with the characters XML cannot carry written as character references."""
    return _INVALID_XML.sub(invalid_char_replacer, text)


def cdata(cdata_text: str) -> str:
    return f"<![CDATA[\n{cdata_text}\n]]>"


class TestInfo:
    """What went wrong in a case: its type and text."""

    __test__ = False  # not a test for pytest

    def __init__(self, type_: str, text: str) -> None:
        self.type = type_
        self.text = text

    def _xml_element(self, tag: str) -> ET.Element:
        element = ET.Element(tag, {"type": self.type})
        element.text = filter_nonprintable_text(self.text)
        return element


class TestError(TestInfo):
    """An error (the test could not run as written)."""

    def xml_element(self) -> ET.Element:
        return self._xml_element("error")


class TestFailure(TestInfo):
    """A failure (an assertion did not hold)."""

    def xml_element(self) -> ET.Element:
        return self._xml_element("failure")


class TestCaseResult:
    """One case: its failures and errors, time and class."""

    __test__ = False

    def __init__(self, name: str) -> None:
        self.name = name
        self.failures: List[TestFailure] = []
        self.errors: List[TestError] = []
        self.time = 0.0
        self.classname = ""

    @property
    def passed(self) -> bool:
        return not self.errors and not self.failures

    @property
    def failure_description(self) -> str:
        return "".join(f"[{self.classname}/{self.name}][FAILURE]\n{f.text}\n" for f in self.failures)

    @property
    def error_description(self) -> str:
        return "".join(f"[{self.classname}/{self.name}][ERROR]\n{e.text}\n" for e in self.errors)

    @property
    def description(self) -> str:
        if self.passed:
            return f"[{self.classname}/{self.name}][passed]\n"
        return self.failure_description + self.error_description

    def add_failure(self, failure: TestFailure) -> None:
        self.failures.append(failure)

    def add_error(self, error: TestError) -> None:
        self.errors.append(error)

    def xml_element(self) -> ET.Element:
        element = ET.Element("testcase", {"classname": self.classname, "name": self.name,
                                          "time": str(self.time)})
        for info in self.failures + self.errors:
            element.append(info.xml_element())
        return element

    def xml(self) -> str:
        return ET.tostring(self.xml_element(), encoding="unicode")


class Result:
    """A suite's counts and cases (the sum of several, after :meth:`accumulate`)."""

    def __init__(self, name: str, num_errors: int = 0, num_failures: int = 0,
                 num_tests: int = 0) -> None:
        self.name = name
        self.num_errors = num_errors
        self.num_failures = num_failures
        self.num_tests = num_tests
        self.test_case_results: List[TestCaseResult] = []
        self.system_out = ""
        self.system_err = ""
        self.time = 0.0

    def accumulate(self, r: Result) -> None:
        self.num_errors += r.num_errors
        self.num_failures += r.num_failures
        self.num_tests += r.num_tests
        self.time += r.time
        self.test_case_results.extend(r.test_case_results)
        if r.system_out:
            self.system_out += "\n" + r.system_out
        if r.system_err:
            self.system_err += "\n" + r.system_err

    def add_test_case_result(self, r: TestCaseResult) -> None:
        self.test_case_results.append(r)

    def xml_element(self) -> ET.Element:
        suite = ET.Element("testsuite", {"tests": str(self.num_tests), "failures": str(self.num_failures),
                                         "time": str(self.time), "errors": str(self.num_errors),
                                         "name": self.name})
        for case in self.test_case_results:
            suite.append(case.xml_element())
        ET.SubElement(suite, "system-out").text = filter_nonprintable_text(self.system_out)
        ET.SubElement(suite, "system-err").text = filter_nonprintable_text(self.system_err)
        return suite

    def xml(self) -> str:
        return '<?xml version="1.0" encoding="utf-8"?>' + ET.tostring(self.xml_element(), encoding="unicode")


def _from_results(results: testing.Results) -> Result:
    out = Result(results.name, results.num_errors, results.num_failures, results.num_tests)
    for case in results.cases:
        r = TestCaseResult(case.name)
        r.classname, r.time = case.classname, case.time
        if case.failure is not None:
            r.add_failure(TestFailure("AssertionError", case.failure))
        if case.error is not None:
            r.add_error(TestError("Exception", case.error))
        out.add_test_case_result(r)
        out.time += case.time
    return out


def read(test_file: str, test_name: str) -> Result:
    """The results in JUnit file ``test_file``; a file that cannot be read counts as one error
    (rosunit's way: the test did not produce results)."""
    try:
        return _from_results(testing.read_results(test_file, test_name))
    except testing.ResultsError as exc:
        result = Result(test_name, num_errors=1, num_tests=1)
        case = TestCaseResult("test_ran")
        case.add_error(TestError("ParseError", str(exc)))
        result.add_test_case_result(case)
        return result


def read_all(filter_: Sequence[str] = ()) -> Result:
    """Every results file below the test results folder (of the packages in ``filter_``)."""
    root = rosenv.test_results_dir()
    total = Result("ros")
    if not root.is_dir():
        return total
    for folder in sorted(p for p in root.iterdir() if p.is_dir()):
        if filter_ and folder.name not in filter_:
            continue
        for f in sorted(folder.glob("*.xml")):
            total.accumulate(read(str(f), f.stem))
    return total


def test_failure_junit_xml(test_name: str, message: str, stdout: Optional[str] = None,
                           class_name: str = "Results", testcase_name: str = "test_ran") -> str:
    """A JUnit file for a test that failed before it could report."""
    suite = ET.Element("testsuite", {"tests": "1", "failures": "1", "time": "1", "errors": "0",
                                     "name": test_name})
    case = ET.SubElement(suite, "testcase", {"name": testcase_name, "status": "run",
                                              "time": "1", "classname": class_name})
    ET.SubElement(case, "failure", {"message": message, "type": ""})
    if stdout:
        ET.SubElement(suite, "system-out").text = filter_nonprintable_text(stdout)
    return '<?xml version="1.0" encoding="utf-8"?>' + ET.tostring(suite, encoding="unicode")


def test_success_junit_xml(test_name: str, class_name: str = "Results",
                           testcase_name: str = "test_ran") -> str:
    suite = ET.Element("testsuite", {"tests": "1", "failures": "0", "time": "1", "errors": "0",
                                     "name": test_name})
    ET.SubElement(suite, "testcase", {"name": testcase_name, "status": "run", "time": "1",
                                      "classname": class_name})
    return '<?xml version="1.0" encoding="utf-8"?>' + ET.tostring(suite, encoding="unicode")


def print_summary(junit_results: Result, runner_name: str = "ROSUNIT") -> None:
    """rosunit's summary block of ``junit_results``."""
    results = testing.Results(junit_results.name, num_errors=junit_results.num_errors,
                              num_failures=junit_results.num_failures,
                              num_tests=junit_results.num_tests)
    for r in junit_results.test_case_results:
        results.cases.append(testing.CaseResult(
            r.name, r.classname, r.time,
            failure="\n".join(f.text for f in r.failures) if r.failures else None,
            error="\n".join(e.text for e in r.errors) if r.errors else None))
    sys.stdout.write(testing.summary_text(results, runner_name=runner_name))


# ---------------------------------------------------------------------------------------------
# rosunit.core

def printlog(msg: str, *args: Any) -> None:
    print("[ROSUNIT]" + (msg % args if args else msg))


def printlog_bold(msg: str, *args: Any) -> None:
    print("\033[1m[ROSUNIT]" + (msg % args if args else msg) + "\033[0m")


def printerrlog(msg: str, *args: Any) -> None:
    print("[ROSUNIT]" + (msg % args if args else msg), file=sys.stderr)


def xml_results_file(test_pkg: str, test_name: str, is_rostest: bool = False,
                     env: Any = None) -> str:
    """``<test results dir>/<pkg>/{rostest,rosunit}-<name>.xml``."""
    return str(testing.results_file(test_pkg, test_name, is_rostest, env))


def rostest_name_from_path(pkg_dir: str, test_file: str) -> str:
    """A test's name from its file: its path in the package, '/' and '.' as '_'."""
    test_file_abs = os.path.abspath(test_file)
    if test_file_abs.startswith(pkg_dir):
        test_file = test_file_abs[len(pkg_dir):]
    if test_file[0] == os.sep:
        test_file = test_file[1:]
    name = test_file.replace(os.sep, "_")
    return name[: name.rfind(".")] if "." in name else name


def create_xml_runner(test_pkg: str, test_name: str, results_file: Optional[str] = None,
                      is_rostest: bool = False) -> XMLTestRunner:
    """A runner writing its JUnit file where rosunit writes it (or to ``results_file``)."""
    path = results_file or xml_results_file(test_pkg, test_name, is_rostest)
    printlog(f"Outputting test results to {path}")
    return XMLTestRunner(path, test_name)


# ---------------------------------------------------------------------------------------------
# rosunit.xmlrunner

class XMLTestRunner:
    """Runs a unittest suite and writes its JUnit file (``stream`` is a path or a file)."""

    def __init__(self, stream: Any = None, suite_name: str = "") -> None:
        self.stream = stream
        self.suite_name = suite_name

    def run(self, test: Any) -> unittest.TestResult:
        runner = unittest.TextTestRunner(stream=testing._NullStream(), verbosity=0,
                                         resultclass=testing._RecordingResult)
        started = time.monotonic()
        result = runner.run(test)
        name = self.suite_name or getattr(test, "id", lambda: "")() or "unittest"
        cases: Iterable[testing.CaseResult] = result.cases  # type: ignore[attr-defined]
        if isinstance(self.stream, (str, Path)):
            testing.write_junit(self.stream, name, list(cases), time.monotonic() - started)
        elif self.stream is not None:
            import tempfile

            with tempfile.TemporaryDirectory() as folder:
                path = Path(folder) / "results.xml"
                testing.write_junit(path, name, list(cases), time.monotonic() - started)
                self.stream.write(path.read_text())
        return result


# ---------------------------------------------------------------------------------------------
# rosunit.baretest's summaries (rostest.rostestutil uses them)

def print_runner_summary(runner_results: unittest.TestResult, junit_results: Result,
                         runner_name: str = "ROSUNIT") -> None:
    """The summary of the test nodes' results, and of the runner's own checks (a test node
    that never reported counts as an error)."""
    total = Result(runner_name)
    total.accumulate(junit_results)
    total.num_errors += len(runner_results.errors)
    total.num_failures += len(runner_results.failures)
    print_summary(total, runner_name=runner_name)


def print_unittest_summary(result: unittest.TestResult) -> None:
    """unittest's counts in rosunit's words."""
    print("\n[ROSUNIT] SUMMARY")
    print(" * RESULT: SUCCESS" if result.wasSuccessful() else " * RESULT: FAIL")
    print(f" * TESTS: {result.testsRun}")
    print(f" * ERRORS: {len(result.errors)}")
    print(f" * FAILURES: {len(result.failures)}")
