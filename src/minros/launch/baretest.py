"""rosunit.baretest and rosunit.rosunit_main: a test program run as one unittest case.

:class:`BareTestCase` runs an executable (a ``.py`` file under minros's interpreter) with
``--gtest_output=xml:FILE`` under a process monitor, fails when it overruns its time limit or
leaves no results, and reads its JUnit results back; the ``rosunit`` command
(:func:`rosunit_main`) runs one such case and writes the wrapper's own JUnit file
(``<ROS_TEST_RESULTS_DIR>/<pkg>/rostest-<name>.xml``) beside the program's
(``rosunit-<name>.xml``), then prints rosunit's summary.
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
import unittest
from typing import Any, List, Optional, Sequence

from minros import packages
from minros.launch import procmon
from minros.launch.nodeproc import LocalProcess as _NodeProcess
from minros.tools import junitxml
from minros.tools.junitxml import printerrlog, printlog, xml_results_file

BARE_TIME_LIMIT = 60.0
TIMEOUT_SIGINT = 15.0  # seconds
TIMEOUT_SIGTERM = 2.0  # seconds


class TestTimeoutException(Exception):
    """A test program ran longer than its time limit."""


class LocalProcess(_NodeProcess):
    """A program on this machine with rosunit's signature (no ROS node arguments unless
    ``is_node``) and its stop timeouts (SIGINT, then SIGTERM after 15 s, SIGKILL 2 s later)."""

    def __init__(self, run_id: Optional[str], package: str, name: str, args: List[str],
                 env: Any, log_output: bool, respawn: bool = False, required: bool = False,
                 cwd: Optional[str] = None, is_node: bool = True) -> None:
        super().__init__(run_id, package, name, list(args), env, log_output, respawn=respawn,
                         required=required, cwd=cwd, is_node=is_node,
                         sigint_timeout=TIMEOUT_SIGINT, sigterm_timeout=TIMEOUT_SIGTERM)


def _package_of(path: str) -> Optional[str]:
    return packages.get_dir_pkg(os.path.dirname(os.path.abspath(path)))[1]


class BareTestCase(unittest.TestCase):
    """One test program as a unittest case: run, wait (bounded), read its results."""

    def __init__(self, exe: str, args: Sequence[str], retry: int = 0,
                 time_limit: Optional[float] = None, test_name: Optional[str] = None,
                 text_mode: bool = False, package_name: Optional[str] = None) -> None:
        super().__init__()
        self.text_mode = text_mode
        self.package = package_name or _package_of(exe)
        self.exe = os.path.abspath(exe)
        self.test_name = test_name if test_name is not None else os.path.basename(exe)
        # a Python test runs under this interpreter (minros's), not whatever `python` is
        self.args = ([sys.executable, self.exe] if self.exe.endswith(".py") else [self.exe]) \
            + list(args)
        if text_mode:
            self.args.append("--text")
        self.retry = retry
        self.time_limit = time_limit or BARE_TIME_LIMIT
        self.pmon: Any = None
        self.results = junitxml.Result(self.test_name)
        self._stop = threading.Event()

    def setUp(self) -> None:  # noqa: N802 - unittest's name
        self.pmon = procmon.start_process_monitor()

    def tearDown(self) -> None:  # noqa: N802
        if self.pmon is not None:
            procmon.shutdown_process_monitor(self.pmon)
            self.pmon = None

    def runTest(self) -> None:  # noqa: N802
        self.assertFalse(self.package is None, "unable to determine package of executable")
        test_name = self.test_name
        while True:
            printlog("Running test [%s]", test_name)
            test_file = xml_results_file(str(self.package), test_name, False)
            if os.path.exists(test_file):
                printlog("removing previous test results file [%s]", test_file)
                os.remove(test_file)
            args = [*self.args, f"--gtest_output=xml:{test_file}"]
            printlog(f"running test {test_name}")
            process = LocalProcess(None, str(self.package), test_name, args, os.environ, False,
                                   cwd="cwd", is_node=False)
            if self.pmon is not None:
                self.pmon.register(process)
            self.assertTrue(process.start(), "test failed to start")
            timed_out = not self._wait(process)
            if timed_out:
                process.stop()
                if not self.retry:
                    raise TestTimeoutException("test max time allotted")
                printerrlog(f"test [{test_name}] timed out")
            else:
                printlog(f"test [{test_name}] finished")
            results = self.results
            failed = timed_out
            if not self.text_mode and not timed_out:
                self.assertTrue(os.path.isfile(test_file),
                                f"test [{test_name}] did not generate test results")
                printlog("test [%s] results are in [%s]", test_name, test_file)
                results = junitxml.read(test_file, test_name)
                failed = bool(results.num_errors or results.num_failures)
            if self.retry > 0 and failed:
                self.retry -= 1
                printlog(f"test [{test_name}] failed, retrying. Retries left: {self.retry}")
                continue
            self.results = results
            printlog("test [%s] results summary: %s errors, %s failures, %s tests", test_name,
                     results.num_errors, results.num_failures, results.num_tests)
            break
        printlog("[ROSTEST] test [%s] done", test_name)

    def _wait(self, process: LocalProcess) -> bool:
        """Whether ``process`` ended within the time limit (polled: it is not our child to
        wait on once the monitor has it)."""
        import time

        deadline = time.monotonic() + self.time_limit
        while process.is_alive():
            if time.monotonic() > deadline:
                return False
            self._stop.wait(0.05)
        return True


def rosunit_main(argv: Sequence[str], prog: str = "rosunit") -> int:
    """``rosunit [options] <file> [test args...]``; the exit status is 1 when the runner's own
    check failed (the program did not run or report), 2 when the program's tests failed."""
    parser = argparse.ArgumentParser(prog=prog, usage=f"{prog} [options] <file> [test args...]",
                                     description="Run a test program (a Python unittest file "
                                     "or an executable taking --gtest_output) and collect its "
                                     "JUnit results.")
    parser.add_argument("-t", "--text", action="store_true", dest="text_mode",
                        help="Run with stdout output instead of XML output")
    parser.add_argument("--time-limit", metavar="TIME_LIMIT", dest="time_limit", default=60,
                        help="Set time limit for test")
    parser.add_argument("--name", metavar="TEST_NAME", dest="test_name", default=None,
                        help="Test name")
    parser.add_argument("--package", metavar="PACKAGE_NAME", dest="pkg", default=None,
                        help="Package name (optional)")
    options, args = parser.parse_known_args(list(argv))
    if not args:
        parser.error("You must supply a test file.")
    test_file = args[0]
    if not os.path.exists(test_file):
        print(f"{prog}: error: no such test file: {test_file}", file=sys.stderr)
        return 1
    test_name = options.test_name or os.path.basename(test_file).rsplit(".", 1)[0]
    try:
        time_limit = float(options.time_limit) if options.time_limit else None
    except ValueError:
        parser.error(f"--time-limit must be a number of seconds, not {options.time_limit!r}")
    pkg = options.pkg or _package_of(test_file)
    if not pkg:
        print(f"Error: failed to determine package name for file '{test_file}'; maybe you "
              "should supply the --package argument to rosunit?")
        return 1
    runner_result = None
    case = BareTestCase(test_file, args[1:], retry=0, time_limit=time_limit, test_name=test_name,
                        text_mode=options.text_mode, package_name=pkg)
    suite = unittest.TestSuite([case])
    try:
        if options.text_mode:
            unittest.TextTestRunner(stream=sys.stdout, verbosity=2).run(suite)
        else:
            results_file = xml_results_file(pkg, test_name, True)
            runner = junitxml.create_xml_runner(pkg, test_name, results_file=results_file,
                                                is_rostest=True)
            runner_result = runner.run(suite)
    finally:
        procmon.pmon_shutdown()
    results = case.results
    if options.text_mode:
        print("WARNING: overall test result is not accurate when --text is enabled")
    else:
        assert runner_result is not None
        junitxml.print_runner_summary(runner_result, results)
    if runner_result is not None and not runner_result.wasSuccessful():
        return 1
    if results.num_errors or results.num_failures:
        return 2
    return 0
