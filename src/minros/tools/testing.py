"""rosunit's part of ROS testing: unittest results as JUnit XML, read back and summed up.

A test node (``rostest.rosrun(pkg, name, TestCase)``) runs its unittest suite and writes the
result where rostest told it to (``--gtest_output=xml:FILE``), or prints it (``--text``);
rostest reads each file back (:func:`read_results`) and prints the summary
(:func:`summary_text`) with rosunit's wording.
"""

from __future__ import annotations

import sys
import time
import unittest
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, List, Sequence

from minros import rosenv

XML_OUTPUT_FLAG = "--gtest_output=xml:"
#: characters rosunit replaces by '_' in a test name used as a file name
_UNSAFE = " \"'&$!`/\\"


def results_file(test_pkg: str, test_name: str, is_rostest: bool = False,
                 env: Any = None) -> Path:
    """``<test results dir>/<pkg>/{rostest,rosunit}-<name>.xml`` (the folder is created)."""
    folder = rosenv.test_results_dir(env) / test_pkg
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OSError(f"cannot create test results directory [{folder}]: {exc.strerror}") from None
    for c in _UNSAFE:
        test_name = test_name.replace(c, "_")
    return folder / f"{'rostest' if is_rostest else 'rosunit'}-{test_name}.xml"


@dataclass
class CaseResult:
    """One test case of a JUnit file."""

    name: str
    classname: str = ""
    time: float = 0.0
    failure: str | None = None
    error: str | None = None
    #: rosunit's name of the file the case was read from (``<folder>.<file stem>``)
    suite: str = ""

    @property
    def passed(self) -> bool:
        return self.failure is None and self.error is None

    @property
    def description(self) -> str:
        """rosunit's text for the case: ``[suite/name][passed]``, or for a failure or error
        the line padded with dashes to 80 columns, its text, and a line of dashes."""
        label = f"{self.suite}/{self.name}" if self.suite else f"{self.classname}/{self.name}"
        if self.passed:
            return f"[{label}][passed]\n"
        text = ""
        for state, detail in (("FAILURE", self.failure), ("ERROR", self.error)):
            if detail is not None:
                head = f"[{label}][{state}]"
                text += head + "-" * (80 - len(head)) + f"\n{detail}\n" + "-" * 80 + "\n\n"
        return text


@dataclass
class Results:
    """The sum of one or more JUnit files."""

    name: str = ""
    cases: List[CaseResult] = field(default_factory=list)
    num_errors: int = 0
    num_failures: int = 0
    num_tests: int = 0

    def add(self, other: Results) -> None:
        self.cases += other.cases
        self.num_errors += other.num_errors
        self.num_failures += other.num_failures
        self.num_tests += other.num_tests

    @property
    def ok(self) -> bool:
        return self.num_errors == 0 and self.num_failures == 0


# ---------------------------------------------------------------------------------------------
# writing

class _RecordingResult(unittest.TextTestResult):
    """A unittest result that remembers every case with its time, for the JUnit file."""

    def __init__(self, *args: Any, **kwds: Any) -> None:
        super().__init__(*args, **kwds)
        self.cases: List[CaseResult] = []
        self._started = 0.0

    def startTest(self, test: unittest.TestCase) -> None:  # noqa: N802 - unittest's name
        self._started = time.monotonic()
        super().startTest(test)

    def _case(self, test: unittest.TestCase) -> CaseResult:
        case = CaseResult(getattr(test, "_testMethodName", str(test)),
                          f"{type(test).__module__}.{type(test).__name__}",
                          time.monotonic() - self._started)
        self.cases.append(case)
        return case

    def addSuccess(self, test: unittest.TestCase) -> None:  # noqa: N802
        super().addSuccess(test)
        self._case(test)

    def addFailure(self, test: unittest.TestCase, err: Any) -> None:  # noqa: N802
        super().addFailure(test, err)
        self._case(test).failure = self._exc_info_to_string(err, test)

    def addError(self, test: unittest.TestCase, err: Any) -> None:  # noqa: N802
        super().addError(test, err)
        if isinstance(test, unittest.TestCase):
            self._case(test).error = self._exc_info_to_string(err, test)
        else:  # a class or module fixture failed
            self.cases.append(CaseResult(str(test), "", 0.0, error=self._exc_info_to_string(err, test)))


def write_junit(path: str | Path, suite_name: str, cases: Sequence[CaseResult],
                total_time: float, stdout: str = "") -> None:
    """Write ``cases`` as one JUnit ``<testsuite>`` (the format rosunit writes)."""
    suite = ET.Element("testsuite", {
        "name": suite_name, "tests": str(len(cases)),
        "errors": str(sum(1 for c in cases if c.error is not None)),
        "failures": str(sum(1 for c in cases if c.failure is not None)),
        "time": f"{total_time:.3f}"})
    for case in cases:
        element = ET.SubElement(suite, "testcase", {"classname": case.classname, "name": case.name,
                                                    "time": f"{case.time:.3f}"})
        if case.failure is not None:
            ET.SubElement(element, "failure", {"type": "AssertionError", "message": ""}).text = case.failure
        if case.error is not None:
            ET.SubElement(element, "error", {"type": "Exception", "message": ""}).text = case.error
    ET.SubElement(suite, "system-out").text = stdout
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(suite).write(str(path), encoding="utf-8", xml_declaration=True)


def run_suite(package: str, test_name: str, test: Any, sysargs: Sequence[str] | None = None
              ) -> unittest.TestResult:
    """Run a TestCase class (or a dotted name) as a rostest/rosunit node does: the JUnit file
    goes where ``--gtest_output=xml:FILE`` says (else the default results file), ``--text``
    prints the cases instead."""
    sysargs = list(sys.argv if sysargs is None else sysargs)
    result_path = None
    for arg in sysargs:
        if arg.startswith(XML_OUTPUT_FLAG):
            result_path = arg[len(XML_OUTPUT_FLAG):]
    loader = unittest.TestLoader()
    suite = loader.loadTestsFromName(test) if isinstance(test, str) else \
        loader.loadTestsFromTestCase(test)
    text_mode = "--text" in sysargs
    stream = sys.stderr if text_mode else _NullStream()
    runner = unittest.TextTestRunner(stream=stream, verbosity=2 if text_mode else 0,
                                     resultclass=_RecordingResult)
    started = time.monotonic()
    result = runner.run(suite)
    if not text_mode:
        path = result_path or str(results_file(package, test_name))
        print(f"[ROSUNIT] Outputting test results to {path}")
        write_junit(path, test_name, result.cases, time.monotonic() - started)  # type: ignore[attr-defined]
    return result


class _NullStream:
    @staticmethod
    def write(_text: str) -> None:
        pass

    @staticmethod
    def flush() -> None:
        pass


# ---------------------------------------------------------------------------------------------
# reading and summing up

class ResultsError(ValueError):
    """A results file that is not JUnit XML."""


def read_results(path: str | Path, test_name: str) -> Results:
    """The counts and cases of a JUnit file (a ``<testsuite>`` or ``<testsuites>``)."""
    try:
        root = ET.parse(str(path)).getroot()
    except (ET.ParseError, OSError) as exc:
        raise ResultsError(f"cannot read test results [{path}]: {exc}") from None
    suites = [root] if root.tag == "testsuite" else root.findall("testsuite")
    results = Results(test_name)
    # rosunit names the cases after the file: <folder>.<name without TEST- and .xml>/<case>
    stem = Path(path).name
    stem = stem[5:] if stem.startswith("TEST-") else stem
    stem = stem[:-4] if stem.endswith(".xml") else stem
    suite_name = f"{Path(path).absolute().parent.name}.{stem}"
    for suite in suites:
        for element in suite.iter("testcase"):
            case = CaseResult(element.get("name", "") or "unknown", element.get("classname", ""),
                              float(element.get("time", "0") or 0), suite=suite_name)
            failure, error = element.find("failure"), element.find("error")
            if failure is not None:
                case.failure = (failure.text or "").strip() or failure.get("message", "")
            if error is not None:
                case.error = (error.text or "").strip() or error.get("message", "")
            results.cases.append(case)
        results.num_tests += int(suite.get("tests", "0") or 0)
        results.num_errors += int(suite.get("errors", "0") or 0)
        results.num_failures += int(suite.get("failures", "0") or 0)
    return results


def summary_text(results: Results, failed_to_run: Sequence[str] = (), runner_name: str = "ROSTEST",
                 color: bool = True) -> str:
    """rosunit's summary block (print_runner_summary): each case's description, a
    ``[test<name>][failed]`` line per test that did not run properly, then RESULT, TESTS,
    ERRORS and FAILURES, coloured as ROS colours them (always, terminal or not)."""
    def paint(code: str, text: str) -> str:
        return f"\033[{code}m{text}\033[0m" if color else text

    text = f"[{runner_name}]" + "-" * 71 + "\n\n"
    text += "".join(c.description for c in results.cases)
    text += "".join(f"[test{name}][failed]\n" for name in failed_to_run)
    ok = results.ok and not failed_to_run
    lines = ["", "SUMMARY",
             paint("32", " * RESULT: SUCCESS") if ok else paint("1;31", " * RESULT: FAIL"),
             f" * TESTS: {results.num_tests}"]
    errors = results.num_errors
    lines.append(paint("1;31", f" * ERRORS: {errors}") if errors else " * ERRORS: 0")
    failures = results.num_failures + len(failed_to_run)
    lines.append(paint("1;31", f" * FAILURES: {failures}") if failures else " * FAILURES: 0")
    if failed_to_run:
        lines += ["", "ERROR: The following tests failed to run:"]
        lines += [f" * test{name}" for name in failed_to_run]
    return text + "\n".join(lines) + "\n"

