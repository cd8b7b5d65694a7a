"""Fixtures shared by every test directory; the machinery lives in tests/support.py."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

# pytest keeps each test module's assert-rewritten bytecode in __pycache__ unless bytecode
# writing is off (PYTHONDONTWRITEBYTECODE, set on some machines): then every run parses and
# rewrites all ~200 modules again, 6 of the quick tier's CPU-seconds. The caches are ignored by
# git; scripts/test.sh unsets the variable for the processes tests start too.
sys.dont_write_bytecode = False
sys.path.insert(0, str(Path(__file__).resolve().parent))
# the page tests' harness (tests/web/page_support.py) beside the pages' sources
sys.path.insert(0, str(Path(__file__).resolve().parent / "web"))

#: a ROS package the rostest tests run: its test_*.py are rostest's test nodes, not pytest's
collect_ignore_glob = ["integration/rostest_pkgs/*"]

from support import (  # noqa: E402
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    free_port,
    reference_env,
    require_reference,
    require_tf_reference,
    ros_env,
    wait_for_master,
)


@pytest.fixture
def ros_home(tmp_path: Path) -> Path:
    home = tmp_path / "ros_home"
    (home / "log").mkdir(parents=True)
    return home


@pytest.fixture
def debian_rosmaster(ros_home: Path):
    """Debian's real ``rosmaster --core`` on a free port; yields the port."""
    require_reference()
    port = free_port()
    env = reference_env(ros_env(port, ros_home))
    proc = Proc(["/usr/bin/rosmaster", "--core", "-p", str(port)], env)
    try:
        wait_for_master(port)
        yield port
    finally:
        proc.stop()


@pytest.fixture
def minros_master(ros_home: Path):
    """minros's bare master (``python -m minros.master -p PORT``); yields the port."""
    port = free_port()
    proc = Proc([PYTHON, "-m", "minros.master", "-p", str(port)], ros_env(port, ros_home))
    try:
        wait_for_master(port)
        yield port
    finally:
        proc.stop()


@pytest.fixture
def minros_core(ros_home: Path):
    """``minros core -p PORT`` (master, roscore parameters and rosout); yields the port."""
    port = free_port()
    proc = Proc([PYTHON, "-m", "minros", "core", "-p", str(port)], ros_env(port, ros_home))
    try:
        wait_for_master(port)
        yield port
    finally:
        proc.stop()


@pytest.fixture(scope="module")
def tf_oracle():
    """Debian's tf2_py and tf.transformations in one /usr/bin/python3 process
    (minros.tf.testing.TfOracle), one per test module."""
    require_tf_reference()
    from minros.tf.testing import TfOracle

    oracle = TfOracle(env=reference_env({}))
    yield oracle
    oracle.close()


__all__ = ["PYTHON", "REFERENCE_PYTHON", "Proc", "free_port", "reference_env", "ros_env"]


#: the fixtures above that start processes: a test using one is `slow` (below)
PROCESS_FIXTURES = {"debian_rosmaster", "minros_master", "minros_core", "tf_oracle"}
#: tests per xdist group: a longer file (parametrized property tests) is cut into groups
GROUP_SIZE = 200


def pytest_collection_modifyitems(config, items) -> None:
    """Every hypothesis test is in the `fuzz` tier (property and fuzz tests, many examples
    each): `pytest tests/unit -m "not slow and not fuzz"` is the quick run, and CI runs every
    tier. A test using a fixture that starts a process is `slow`; every test of tests/unit is
    `unit` (the other Pythons' runs in scripts/test.sh select `unit or smoke`)."""
    for item in items:
        if getattr(getattr(item, "obj", None), "is_hypothesis_test", False):
            item.add_marker(pytest.mark.fuzz)
        if PROCESS_FIXTURES.intersection(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.slow)
        if UNIT in item.path.parents:
            item.add_marker(pytest.mark.unit)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """--dist loadfile (scripts/test.sh), with files cut: a test file is one unit of work, so
    that it runs in one worker, in its order, with its module fixtures set up once; a file of
    more than GROUP_SIZE tests (parametrized property tests) is cut into units of GROUP_SIZE
    consecutive tests, so that it does not hold one worker while the others are idle.
    (xdist's own loadgroup cannot do it under pytest 9: its group suffix on the test ids is
    lost.)"""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class FileUnits(LoadFileScheduling):
        def __init__(self, config, log) -> None:
            super().__init__(config, log)
            self.units: dict = {}

        def _split_scope(self, nodeid: str) -> str:
            if not self.units and self.collection:
                counts: dict = {}
                for test in self.collection:
                    name = test.split("::", 1)[0]
                    counts[name] = counts.get(name, 0) + 1
                seen: dict = {}
                for test in self.collection:
                    name = test.split("::", 1)[0]
                    index = seen[name] = seen.get(name, -1) + 1
                    self.units[test] = (name if counts[name] <= GROUP_SIZE
                                        else f"{name}#{index // GROUP_SIZE}")
            return self.units.get(nodeid) or super()._split_scope(nodeid)

    return FileUnits(config, log)


# The quick tier runs in one process: a test of tests/unit that starts one (a node, a master,
# Debian's Python as an oracle, a command) is marked `slow`. Every way a process starts is
# patched while such a test sets up, runs and tears down; an attempt fails the test, naming
# the program, even when the code under test catches the error the attempt raises.
UNIT = Path(__file__).resolve().parent / "unit"


class ProcessStartedError(OSError):
    """Raised where a quick-tier test starts a process."""


class _NoProcesses:
    def __init__(self) -> None:
        import multiprocessing.util
        import subprocess

        self.targets = [(subprocess.Popen, "_execute_child"), (multiprocessing.util, "spawnv_passfds")]
        self.targets += [(os, name) for name in ("fork", "forkpty", "posix_spawn", "posix_spawnp",
                                                 "system", "spawnv", "spawnve", "spawnvp", "spawnvpe")
                         if hasattr(os, name)]
        self.started: list[str] = []
        self._saved: list = []

    def _refuse(self, what: str):
        def refuse(*args, **kwargs):
            argv = next((a for a in args if isinstance(a, (list, tuple, str, bytes))), "")
            self.started.append(f"{what}({str(argv)[:200]})")
            raise ProcessStartedError(f"a quick-tier test started a process: {self.started[-1]}")
        return refuse

    def __enter__(self) -> _NoProcesses:
        for owner, name in self.targets:
            self._saved.append((owner, name, owner.__dict__[name]))
            setattr(owner, name, self._refuse(name))
        return self

    def __exit__(self, *exc) -> None:
        for owner, name, value in self._saved:
            setattr(owner, name, value)
        self._saved.clear()


def _quick(item) -> bool:
    return UNIT in item.path.parents and item.get_closest_marker("slow") is None


def _guarded(item):
    if not _quick(item):
        outcome = yield
        return
    with _NoProcesses() as guard:
        outcome = yield
    if guard.started:
        outcome.force_exception(pytest.fail.Exception(
            f"{item.nodeid} starts a process ({', '.join(guard.started)}): a test of the quick "
            "tier runs in the pytest process; mark it @pytest.mark.slow (see README.md)",
            pytrace=False))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_setup(item):
    yield from _guarded(item)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item):
    yield from _guarded(item)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_teardown(item):
    yield from _guarded(item)


# scripts/test.sh runs again, alone, a test that failed in the parallel run (MINROS_FAILED_LIST
# names the file that gets the failed tests' ids), to tell a race under load from a failure.
_failed: list[str] = []


def pytest_runtest_logreport(report) -> None:
    if report.failed and report.nodeid not in _failed:
        _failed.append(report.nodeid)


def pytest_sessionfinish(session) -> None:
    path = os.environ.get("MINROS_FAILED_LIST")
    if path and not hasattr(session.config, "workerinput"):  # the controller sees every report
        Path(path).write_text("".join(f"{nodeid}\n" for nodeid in _failed))


# MINROS_CPU_LOG=FILE: each pytest process adds a line per test file to FILE, the CPU-seconds its
# tests cost (this process and the processes they started and waited for): where the test
# command's CPU goes (`sort -rn FILE | head` names the costliest files).
_cpu: dict[str, float] = {}


def _cpu_now() -> float:
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    if not os.environ.get("MINROS_CPU_LOG"):
        yield
        return
    start = _cpu_now()
    yield
    name = item.nodeid.split("::", 1)[0]
    _cpu[name] = _cpu.get(name, 0.0) + _cpu_now() - start


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config) -> None:
    path = os.environ.get("MINROS_CPU_LOG")
    if path and _cpu:
        with open(path, "a") as log:
            log.writelines(f"{cpu:.2f}\t{name}\n" for name, cpu in _cpu.items())
