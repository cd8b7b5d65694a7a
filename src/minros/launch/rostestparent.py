"""rostest's Python API: rostest.rostest_parent and rostest.runner over roslaunch's parent.

:class:`ROSTestLaunchParent` is a roslaunch parent (minros.launch.rosserver) for one ``.test``
file: ``setUp()`` starts the process monitor, the XML-RPC server and a master of its own on
``port`` (0: any free port) unless it reuses the running one, ``launch()`` starts the file's
nodes, ``run_test(test)`` runs one ``<test>`` to its end, ``tearDown()`` stops it all.
:func:`createUnitTest` turns a ``.test`` file into a unittest class with one ``test<name>``
method per ``<test>``: each runs the test node with ``--gtest_output=xml:FILE`` and reads its
JUnit results back into the run's totals (:func:`getResults`), as ROS's rostest runner does.
"""

from __future__ import annotations

import logging
import os
import sys
import unittest
from typing import Any, Callable, Dict, List, Optional

from minros import master as _master
from minros.launch.rosmodel import generate_run_id, load_config_default
from minros.launch.rosrunner import RLTestTimeoutException
from minros.launch.rosserver import ROSLaunchParent
from minros.tools import junitxml
from minros.tools.master import Master as _MasterClient
from minros.tools.testing import XML_OUTPUT_FLAG

ROS_TEST_RESULTS_DIR = "ROS_TEST_RESULTS_DIR"
#: parameters ``clear`` keeps on a reused master
_KEPT_PARAMS = ("/run_id", "/rosversion", "/rosdistro")


def printlog(msg: str, *args: Any) -> None:
    """rostest's log line: the log file and the console."""
    msg = msg % args if args else msg
    logging.getLogger("rostest").info(msg)
    print("[ROSTEST]" + msg)


def printlogerr(msg: str, *args: Any) -> None:
    msg = msg % args if args else msg
    logging.getLogger("rostest").error(msg)
    print("[ROSTEST]" + msg, file=sys.stderr)


class _TestMaster:
    """A master of the test's own (rosmaster.master.Master's interface)."""

    def __init__(self, port: int = 0) -> None:
        self.port = port
        self.master_node: Optional[_master.Master] = None
        self.uri: Optional[str] = None

    def start(self) -> None:
        self.master_node = _master.Master(self.port).start()
        self.uri = self.master_node.uri

    def stop(self) -> None:
        if self.master_node is not None:
            self.master_node.stop()
            self.master_node = None


class ROSTestLaunchParent(ROSLaunchParent):
    """A roslaunch parent that runs a ``.test`` file's nodes and then, one by one, its tests."""

    def __init__(self, config: Any, roslaunch_files: Any, port: int = 0,
                 reuse_master: bool = False, clear: bool = False) -> None:
        if config is None:
            raise Exception("config not initialized")
        if reuse_master:
            client = _MasterClient("/roslaunch", timeout=5.0)
            try:
                run_id = client.getParam("/run_id")
            except Exception as exc:  # noqa: BLE001 - rostest's wording for any failure
                raise Exception("Could not connect to existing ROS master. "
                                f"Original exception was: {exc}") from None
            if clear:
                for name in client.getParamNames():
                    if name not in _KEPT_PARAMS and not name.startswith("/roslaunch/"):
                        client.deleteParam(name)
        else:
            run_id = generate_run_id()
        super().__init__(run_id, roslaunch_files, is_core=False, is_rostest=True)
        self.config = config
        self.port = port
        self.reuse_master = reuse_master
        self.master: Optional[_TestMaster] = None

    def _load_config(self) -> None:
        pass  # the config is given

    def setUp(self) -> None:  # noqa: N802 - rostest's name
        """The process monitor, the server, the master (unless reused) and the runner."""
        self._start_infrastructure()
        if not self.reuse_master:
            self.master = _TestMaster(self.port)
            self.master.start()
            self.config.master.uri = self.master.uri
        self._init_runner()

    def tearDown(self) -> None:  # noqa: N802
        if self.runner is not None:
            self.runner.stop()
        if self.master is not None:
            self.master.stop()
            self.master = None
        self._stop_infrastructure()

    def launch(self) -> Any:
        """Start the file's nodes (not its tests): ``(started, failed)``."""
        if self.runner is None:
            raise Exception("no runner to launch")
        return self.runner.launch()

    def run_test(self, test: Any) -> None:
        """Run one ``<test>`` to its end (RLTestTimeoutException past its time limit)."""
        if self.runner is None:
            raise Exception("no runner")
        self.runner.run_test(test)


# ---------------------------------------------------------------------------------------------
# rostest.runner: the run's state is module-wide, as in ROS

_results = junitxml.Result("rostest", 0, 0, 0)
_text_mode = False
_test_parents: List[ROSTestLaunchParent] = []
_config: Any = None


def _accumulate_results(results: junitxml.Result) -> None:
    _results.accumulate(results)


def getResults() -> junitxml.Result:  # noqa: N802 - rostest's names
    """The sum of every test's results so far."""
    return _results


def setTextMode(val: bool) -> None:  # noqa: N802
    """Tests print to the console (``--text``) instead of writing results."""
    global _text_mode
    _text_mode = bool(val)


def getConfig() -> Any:  # noqa: N802
    return _config


def getRostestParents() -> List[ROSTestLaunchParent]:  # noqa: N802
    return _test_parents


def _add_rostest_parent(parent: ROSTestLaunchParent) -> None:
    global _config
    logging.getLogger("rostest").info("_addRostestParent [%s]", parent)
    _test_parents.append(parent)
    _config = parent.config


def failDuplicateRunner(testName: str) -> Callable[[unittest.TestCase], None]:  # noqa: N802, N803
    """A test method that fails: two ``<test>`` entries share the name."""
    def fn(self: unittest.TestCase) -> None:
        print(f"Duplicate tests named [{testName}] in rostest suite")
        self.fail(f"Duplicate tests named [{testName}] in rostest suite")
    return fn


def failRunner(testName: str, message: str) -> Callable[[unittest.TestCase], None]:  # noqa: N802, N803
    """A test method that fails with ``message`` (the test node cannot be found)."""
    def fn(self: unittest.TestCase) -> None:
        print(message, file=sys.stderr)
        self.fail(message)
    return fn


def rostestRunner(test: Any, test_pkg: str,  # noqa: N802
                  results_base_dir: Optional[str] = None) -> Callable[[Any], None]:
    """The test method that runs ``test`` (a roslaunch Test) and reads its results."""
    def fn(self: Any) -> None:
        test_name = test.test_name
        while True:
            self.assertTrue(self.test_parent is not None, "ROSTestParent initialization failed")
            printlog("Running test [%s]", test_name)
            _succeeded, failed = self.test_parent.launch()
            self.assertTrue(not failed, f"Test Fixture Nodes {failed} failed to launch")
            env = {ROS_TEST_RESULTS_DIR: results_base_dir} if results_base_dir else None
            test_file = junitxml.xml_results_file(test_pkg, test_name, False, env=env)
            if os.path.exists(test_file):
                printlog("removing previous test results file [%s]", test_file)
                os.remove(test_file)
            test.args = f"{test.args} {XML_OUTPUT_FLAG}{test_file}"
            if _text_mode:
                test.output = "screen"
                test.args += " --text"
            printlog(f"running test {test_name}")
            timed_out = False
            try:
                self.test_parent.run_test(test)
            except RLTestTimeoutException:
                if not test.retry:
                    raise
                timed_out = True
            if timed_out:
                printlogerr(f"test [{test_name}] timed out")
            else:
                printlog(f"test [{test_name}] finished")
            if _text_mode and not timed_out:
                if test.retry:
                    printlogerr("retry is disabled in --text mode")
                break
            results = None
            if not timed_out:
                self.assertTrue(os.path.isfile(test_file),
                                f"test [{test_name}] did not generate test results")
                printlog("test [%s] results are in [%s]", test_name, test_file)
                results = junitxml.read(test_file, test_name)
                failing = bool(results.num_errors or results.num_failures)
            else:
                failing = True
            if test.retry > 0 and failing:
                test.retry -= 1
                printlog(f"test [{test_name}] failed, retrying. Retries left: {test.retry}")
                self.tearDown()
                self.setUp()
                continue
            if results is not None:
                _accumulate_results(results)
                printlog("test [%s] results summary: %s errors, %s failures, %s tests",
                         test_name, results.num_errors, results.num_failures, results.num_tests)
            break
        printlog("[ROSTEST] test [%s] done", test_name)
    return fn


def setUp(self: Any) -> None:  # noqa: N802
    """The unittest class's setUp: a fresh launch parent for the file."""
    self.test_parent = ROSTestLaunchParent(self.config, [self.test_file],
                                           reuse_master=self.reuse_master, clear=self.clear)
    printlog("setup[%s] run_id[%s] starting", self.test_file, self.test_parent.run_id)
    self.test_parent.setUp()
    self.config = self.test_parent.config
    _add_rostest_parent(self.test_parent)
    printlog("setup[%s] run_id[%s] done", self.test_file, self.test_parent.run_id)


def tearDown(self: Any) -> None:  # noqa: N802
    printlog("tearDown[%s]", self.test_file)
    if self.test_parent:
        self.test_parent.tearDown()
    printlog("rostest teardown %s complete", self.test_file)


def createUnitTest(pkg: str, test_file: str, reuse_master: bool = False,  # noqa: N802
                   clear: bool = False, results_base_dir: Optional[str] = None) -> type:
    """A unittest class ``RosTest`` for ``test_file``: a ``test<name>`` method per
    ``<test>`` (one that fails at once when its node is missing or its name repeats)."""
    from minros.workspace.executables import find_executables

    config = load_config_default([test_file], None)
    classdict: Dict[str, Any] = {"setUp": setUp, "tearDown": tearDown, "config": config,
                                 "test_parent": None, "test_file": test_file,
                                 "reuse_master": reuse_master, "clear": clear,
                                 "__module__": "rostest.runner"}  # as ROS names its cases
    names: List[str] = []
    for test in config.tests:
        err_msg = None
        try:
            if not find_executables(test.package, test.type):
                err_msg = (f"Test node [{test.package}/{test.type}] does not exist or is not "
                           "executable")
        except Exception:  # noqa: BLE001 - the package is not there
            err_msg = (f"Package [{test.package}] for test node [{test.package}/{test.type}] "
                       "does not exist")
        name = f"test{test.test_name}"
        if err_msg:
            classdict[name] = failRunner(test.test_name, err_msg)
        elif name in names:
            classdict[name] = failDuplicateRunner(test.test_name)
        else:
            classdict[name] = rostestRunner(test, pkg, results_base_dir=results_base_dir)
            names.append(name)
    return type("RosTest", (unittest.TestCase,), classdict)


def write_bad_filename_failure(test_file: str, results_file: str, outname: str) -> None:
    """The JUnit file rostest writes when the test file does not exist: one failed case."""
    os.makedirs(os.path.dirname(results_file) or ".", exist_ok=True)
    result = junitxml.Result(outname, num_failures=1, num_tests=1)
    result.time = 1.0
    case = junitxml.TestCaseResult("test_ran")
    case.classname = "Results"
    case.time = 1.0
    case.add_failure(junitxml.TestFailure("", f"rostest file [{test_file}] does not exist"))
    result.add_test_case_result(case)
    with open(results_file, "w", encoding="utf-8") as f:
        f.write(result.xml())

