"""rostest: run a ``.test`` launch file's nodes on a master of its own, then each ``<test>``.

As ROS's rostest: a master on a free port (or the running one with ``reuse_master``), the
file's parameters and nodes started once, then every ``<test>`` node run to its end (within
its ``time-limit``, retried ``retry`` times) with ``--gtest_output=xml:FILE`` naming where its
unittest results go (``$ROS_HOME/test_results/<pkg>/rosunit-<test-name>.xml``); a test that
leaves no results, times out or cannot start fails. The whole run is written as
``rostest-<file>.xml`` beside them and summed up with rosunit's wording.
"""

from __future__ import annotations

import socket
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, List, Mapping, Sequence

from minros import names
from minros.launch.config import LaunchError, NodeSpec
from minros.launch.loader import load_launch
from minros.launch.runner import LaunchProcess, LaunchRunner
from minros.rosenv import get_master_uri
from minros.tools import testing

Print = Callable[[str], None]


@dataclass
class RostestOutcome:
    """What a run produced: the summed results and the tests that did not run properly."""

    results: testing.Results = field(default_factory=testing.Results)
    failed_to_run: List[str] = field(default_factory=list)
    summary_file: Path | None = None
    #: the run's own cases, ``test<name>`` each, failed with the reason when a test did not run
    cases: List[testing.CaseResult] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.results.ok and not self.failed_to_run


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def summary_file(test_file: str, package: str, pkg_dir: Path | None,
                 results_filename: str | None, env: Mapping[str, str]) -> Path:
    """Where the run's own results go: ``<results>/<pkg>/rostest-<name>.xml`` (the name from
    ``--results-filename`` without its extension, else from the file's path in its package)."""
    if results_filename:
        name = results_filename.rpartition(".")[0] if "." in results_filename else results_filename
    else:
        name = test_file_name(pkg_dir, Path(test_file))
    return testing.results_file(package, name, is_rostest=True, env=env)


def test_file_name(pkg_dir: Path | None, test_file: Path) -> str:
    """rostest's name for a file's results: its path in the package, '/' -> '_', no suffix."""
    path = test_file.resolve()
    try:
        relative = path.relative_to(pkg_dir.resolve()) if pkg_dir else Path(path.name)
    except ValueError:
        relative = Path(path.name)
    return str(relative.with_suffix("")).replace("/", "_")


class _TestRun:
    def __init__(self, runner: LaunchRunner, package: str, text: bool, env: Mapping[str, str],
                 out: Print, err: Print) -> None:
        self.runner = runner
        self.package = package
        self.text = text
        self.env = env
        self.out = out
        self.err = err

    def run(self, spec: NodeSpec) -> tuple:
        """``(results or None, why it failed to run or None)`` of one ``<test>``."""
        name = spec.test_name or spec.name
        path = testing.results_file(self.package, name, env=self.env)
        if path.exists():
            path.unlink()
        proc_name = f"{names.ns_join(spec.namespace, spec.name).lstrip('/')}-test"
        try:
            argv, cwd = self.runner.node_command(spec, proc_name)
        except LaunchError as exc:
            return None, f"test [{name}] could not start: {exc.message}"
        argv.append(f"{testing.XML_OUTPUT_FLAG}{path}")
        if self.text:
            argv.append("--text")
        proc = LaunchProcess(proc_name, argv, self.runner.node_env(spec), cwd, spec=spec,
                             log_dir=self.runner.log_dir, screen=self.text or spec.output == "screen")
        Path(cwd).mkdir(parents=True, exist_ok=True)
        self.out(f"running test {name}")
        try:
            proc.start()
        except OSError as exc:
            return None, f"test [{name}] could not start: {' '.join(argv)}: {exc.strerror}"
        limit = spec.time_limit if spec.time_limit is not None else 60.0
        deadline = time.monotonic() + limit
        while proc.poll():
            if time.monotonic() > deadline:
                proc.stop(2.0, 2.0, self.err)
                return None, f"test [{name}] timed out after {limit:g} s"
            if self.runner.shutdown.wait(0.05):
                proc.stop(2.0, 2.0, self.err)
                return None, f"test [{name}] was interrupted"
        proc.stop(0, 0, self.err)
        self.out(f"test [{name}] finished")
        if self.text:
            return testing.Results(name, [testing.CaseResult(f"test{name}", "rostest")],
                                   num_tests=1, num_errors=0,
                                   num_failures=0 if proc.exit_code == 0 else 1), None
        if not path.is_file():
            return None, f"test [{name}] did not generate test results"
        try:
            results = testing.read_results(path, name)
        except testing.ResultsError as exc:
            return None, str(exc)
        self.out(f"test [{name}] results are in [{path}]")
        self.out(f"test [{name}] results summary: {results.num_errors} errors, "
                 f"{results.num_failures} failures, {results.num_tests} tests")
        return results, None


def run_rostest(test_file: str, package: str, pkg_dir: Path | None, argv: Sequence[str] = (), *,
                reuse_master: bool = False, text: bool = False, env: Mapping[str, str],
                results_filename: str | None = None, out: Print = print,
                err: Print = print, loaded: Callable[[], None] | None = None) -> RostestOutcome:
    """Run ``test_file`` (a launch file with ``<test>`` tags); raises LaunchError when the file
    cannot be loaded (a broken ``<test>`` entry included). ``loaded()`` is called once it is."""
    config = load_launch(test_file, list(argv), env=env)
    if loaded is not None:
        loaded()
    if reuse_master:
        master_uri, port = get_master_uri(env), None
    else:
        port = _free_port()
        master_uri = f"http://localhost:{port}/"
    child_env: Dict[str, str] = dict(env)
    child_env["ROS_MASTER_URI"] = master_uri
    # as ROS's rostest: the test's own master comes without rosout (its runner finds a master
    # running and starts no core node), so a <test> named rosout is the only /rosout
    runner = LaunchRunner(config, master_uri=master_uri, env=child_env, port=port, screen=text,
                          core_nodes=False, out=out, err=err)
    outcome = RostestOutcome()
    started = time.monotonic()
    cases: List[testing.CaseResult] = []
    monitor = threading.Thread(target=runner.monitor, name="rostest-monitor", daemon=True)
    try:
        runner.start()
        monitor.start()
        tests = _TestRun(runner, package, text, child_env, out, err)
        for spec in config.tests:
            name = spec.test_name or spec.name
            out(f"[ROSTEST] Running test [{name}]")
            for attempt in range(int(getattr(spec, "retry", 0) or 0) + 1):
                results, problem = tests.run(spec)
                if problem is None and results is not None and results.ok:
                    break
                if attempt < int(getattr(spec, "retry", 0) or 0):
                    out(f"test [{name}] failed, retrying")
            case = testing.CaseResult(f"test{name}", "rostest.runner.RosTest")
            if problem is not None:
                err(f"[ROSTEST] {problem}")
                outcome.failed_to_run.append(name)
                case.failure = problem
            else:
                outcome.results.add(results)
            cases.append(case)
    finally:
        runner.stop()
        monitor.join(timeout=10)
    summary = summary_file(test_file, package, pkg_dir, results_filename, child_env)
    testing.write_junit(summary, "rostest", cases, time.monotonic() - started)
    outcome.summary_file = summary
    outcome.cases = cases
    return outcome
