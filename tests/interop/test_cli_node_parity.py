"""minros's rosnode against Debian's where things go wrong: unknown nodes and machines, empty
namespaces, nothing to clean, bad arguments, no master, and nodes that died without
unregistering.

Both tools run with the same arguments on the same master (Debian's rosmaster and minros's, one
module run each); stdout, stderr and the exit status must agree once ports, pids and times are
masked (tests/compare.py), as in test_cli_oracle.
"""

from __future__ import annotations

import os
import signal
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from compare import Outcome, assert_same, normalize
from support import (
    PYTHON,
    REFERENCE_PYTHON,
    Proc,
    free_port,
    reference_env,
    require_reference,
    ros_env,
    wait_for_master,
)

# The module's fixture runs about 60 rosnode commands per master kind (each bounded by TIMEOUT):
# on two loaded CPUs that setup alone took over pytest-timeout's 120 s, so the module gets 300.
pytestmark = [pytest.mark.interop, pytest.mark.timeout(300)]

DEMO = str(Path(__file__).resolve().parent.parent / "integration" / "cli_demo_node.py")
BIN = Path(PYTHON).parent
TIMEOUT = 20.0


class Side:
    """Runs `rosnode ARGS` as minros and as Debian with one ROS environment."""

    def __init__(self, env: dict) -> None:
        self.env = env
        self.renv = reference_env(env)

    @staticmethod
    def _run(argv: list, env: dict, stdin: str) -> Outcome:
        try:
            done = subprocess.run(argv, env=env, input=stdin, capture_output=True, text=True,
                                  timeout=TIMEOUT)
        except subprocess.TimeoutExpired as exc:
            raise AssertionError(f"{argv} did not finish within {TIMEOUT}s: {exc.stdout}{exc.stderr}") from None
        return Outcome(argv, done.returncode, done.stdout, done.stderr)

    def ours(self, *args: str, stdin: str = "") -> Outcome:
        return self._run([str(BIN / "rosnode"), *args], self.env, stdin)

    def reference(self, *args: str, stdin: str = "") -> Outcome:
        return self._run(["/usr/bin/rosnode", *args], self.renv, stdin)

    def both(self, case: tuple) -> tuple:
        with ThreadPoolExecutor(2) as pool:
            mine = pool.submit(self.ours, *case)
            theirs = pool.submit(self.reference, *case)
            return mine.result(), theirs.result()

    def many(self, cases: list) -> dict:
        with ThreadPoolExecutor(3) as pool:
            return dict(zip(cases, pool.map(self.both, cases)))


# read-only cases on a master without nodes (the stdin is empty: nothing waits for an answer)
EMPTY_CASES = [
    ("info", "/nonexistent"),
    ("info", "-q", "/nonexistent"),
    ("info", "/nonexistent", "/other"),
    ("ping", "/nonexistent"),
    ("ping", "-c", "1", "/nonexistent"),
    ("ping", "-c", "2", "/nonexistent"),
    ("ping", "--all"),
    ("machine", "unknownhost"),
    ("machine", ""),
    ("machine",),
    ("list",),
    ("list", "/ns_without_nodes"),
    ("list", "-a", "/ns_without_nodes"),
    ("list", "-u", "ns_without_nodes"),
    ("cleanup",),
    ("kill",),
    # usage errors and help texts (rosnode parses with optparse)
    ("ping",),
    ("info",),
    ("list", "a", "b"),
    ("machine", "a", "b"),
    ("ping", "-c", "x", "/a"),
    ("ping", "-a", "-c", "2"),
    ("ping", "-a", "/x"),
    ("kill", "-a", "/x"),
    ("cleanup", "x"),
    ("list", "--bogus"),
    ("list", "-h"), ("info", "-h"), ("ping", "-h"), ("kill", "-h"), ("machine", "-h"), ("cleanup", "-h"),
]
NO_MASTER_CASES = [
    ("machine", "unknownhost"), ("machine",), ("info", "/nonexistent"), ("ping", "/nonexistent"),
    ("ping",), ("list",), ("kill", "/nonexistent"), ("cleanup",),
]
DEAD_CASES = [
    ("info", "/dead_rospy"),
    ("info", "/dead_minros"),
    ("info", "-q", "/dead_rospy"),
    ("info", "/dead_minros", "/nonexistent"),
    ("ping", "/dead_rospy"),
    ("ping", "-c", "1", "/dead_minros"),
    ("ping", "--all"),
    ("ping",),
    ("list",),
    ("list", "-a"),
    ("list", "-u"),
    ("machine",),
    ("machine", "localhost"),
    ("kill", "/nonexistent"),
]
DEAD_NODES = ("/dead_minros", "/dead_rospy")
#: rosnode walks these nodes in the order of a Python set (hash order, random per process);
#: minros sorts them, so these outputs are compared line by line regardless of order
UNORDERED = {("ping", "--all")}


def assert_same_lines(ours: Outcome, reference: Outcome) -> None:
    """Same status, and the same lines (masked) on stdout and on stderr in any order."""
    assert ours.status == reference.status, (ours, reference)
    for mine, theirs in ((ours.stdout, reference.stdout), (ours.stderr, reference.stderr)):
        assert sorted(normalize(mine).splitlines()) == sorted(normalize(theirs).splitlines()), (ours, reference)


def _start_master(kind: str, env: dict) -> Proc:
    port = env["ROS_MASTER_URI"].rsplit(":", 1)[1]
    if kind == "debian":
        return Proc(["/usr/bin/rosmaster", "--core", "-p", port], reference_env(env))
    return Proc([PYTHON, "-m", "minros.master", "-p", port], env)


def _register_dead_nodes(side: Side) -> None:
    """A rospy node and a minros node register everything, then die without unregistering."""
    nodes = [Proc([REFERENCE_PYTHON, DEMO, "dead_rospy"], side.renv), Proc([PYTHON, DEMO, "dead_minros"], side.env)]
    try:
        for node in nodes:
            node.read_until("ready", 20)
    finally:
        for node in nodes:
            if node.alive():
                os.killpg(node.popen.pid, signal.SIGKILL)
            node.popen.wait(10)
            node.stop()


class Runs:
    empty: dict
    no_master: dict
    dead: dict
    cleanup: tuple
    after_cleanup: tuple


@pytest.fixture(scope="module", params=["debian", "minros"])
def runs(request, tmp_path_factory) -> Runs:
    """Every case run once per master kind, in the order that changes the graph."""
    require_reference()
    home = tmp_path_factory.mktemp("node_parity") / "ros_home"
    (home / "log").mkdir(parents=True)
    result = Runs()
    result.no_master = Side(ros_env(free_port(), home)).many(NO_MASTER_CASES)
    side = Side(ros_env(free_port(), home))
    master = _start_master(request.param, side.env)
    try:
        wait_for_master(int(side.env["ROS_MASTER_URI"].rsplit(":", 1)[1]))
        result.empty = side.many(EMPTY_CASES)
        _register_dead_nodes(side)
        result.dead = side.many(DEAD_CASES)
        # cleanup mutates the graph: ours first, then the same dead nodes again for Debian's
        ours_n, ref_n = side.ours("cleanup", stdin="n\n"), side.reference("cleanup", stdin="n\n")
        ours = side.ours("cleanup", stdin="y\n")
        ours_state = side.reference("list").stdout, _rostopic_list(side)
        _register_dead_nodes(side)
        reference = side.reference("cleanup", stdin="y\n")
        ref_state = side.reference("list").stdout, _rostopic_list(side)
        result.cleanup = (ours_n, ref_n, ours, reference)
        result.after_cleanup = (ours_state, ref_state)
    finally:
        master.stop()
    return result


def _rostopic_list(side: Side) -> str:
    done = subprocess.run(["/usr/bin/rostopic", "list"], env=side.renv, capture_output=True, text=True,
                          timeout=TIMEOUT)
    return done.stdout


def _ids(cases: list) -> list:
    return [" ".join(c) or "<none>" for c in cases]


@pytest.mark.parametrize("case", EMPTY_CASES, ids=_ids(EMPTY_CASES))
def test_empty_graph_like_rosnode(runs: Runs, case: tuple) -> None:
    assert_same(*runs.empty[case], compare_stderr=True)


def test_usage_text_is_rosnodes(runs: Runs) -> None:
    ours, reference = runs.empty[("list", "-h")]
    assert reference.stdout.startswith("Usage: rosnode list\n\nOptions:\n")
    assert ours.stdout == reference.stdout
    ours, reference = runs.empty[("info",)]
    assert reference.stderr == ("Usage: rosnode info [options] node1 [node2...]\n\n"
                                "rosnode: error: You must specify at least one node name\n")
    assert ours.stderr == reference.stderr
    assert ours.status == reference.status == 2


@pytest.mark.parametrize("case", NO_MASTER_CASES, ids=_ids(NO_MASTER_CASES))
def test_no_master_like_rosnode(runs: Runs, case: tuple) -> None:
    assert_same(*runs.no_master[case], compare_stderr=True)


@pytest.mark.parametrize("case", [c for c in DEAD_CASES if c != ("kill", "/nonexistent")],
                         ids=_ids([c for c in DEAD_CASES if c != ("kill", "/nonexistent")]))
def test_dead_nodes_like_rosnode(runs: Runs, case: tuple) -> None:
    ours, reference = runs.dead[case]
    if case in UNORDERED:
        assert_same_lines(ours, reference)
        assert ours.stdout.index(" * /dead_minros") < ours.stdout.index(" * /dead_rospy")  # sorted
    else:
        assert_same(ours, reference, compare_stderr=True)
    if case[0] in ("info", "ping") and "-q" not in case and len(case) > 1:
        # the dead node is reported, not silently skipped
        assert "failed" in ours.stderr or "refused" in ours.stderr, ours.stderr


def test_dead_nodes_are_reported(runs: Runs) -> None:
    """The comparison above is not vacuous: both tools saw both dead registrations."""
    ours, _reference = runs.dead[("list",)]
    assert ours.stdout.split() == sorted(DEAD_NODES)
    ours, _reference = runs.dead[("info", "/dead_minros")]
    assert ours.status == 1 and "ERROR: Communication with node[http://localhost:" in ours.stderr
    ours, _reference = runs.dead[("ping", "-c", "1", "/dead_minros")]
    assert ours.status == 0 and ours.stderr.startswith("ERROR: connection refused to [http://localhost:")


def test_unknown_node_kill_differs_only_in_layout(runs: Runs) -> None:
    """Deliberate difference: minros names unknown nodes on the one error line (CLI rule: one
    line on stderr); rosnode lists them below it. Status and stdout agree."""
    ours, reference = runs.dead[("kill", "/nonexistent")]
    assert_same(ours, reference)
    assert reference.stderr == "ERROR: Unknown node(s):\n * /nonexistent\n"
    assert ours.stderr == "ERROR: Unknown node(s): /nonexistent\n"


def test_cleanup_answers_like_rosnode(runs: Runs) -> None:
    ours_n, ref_n, ours, reference = runs.cleanup
    assert_same_lines(ours_n, ref_n)
    assert ours_n.stdout.endswith("Please type y or n to continue:\naborting\n")
    assert_same_lines(ours, reference)
    assert ours.status == 0
    assert "Unregistering /dead_minros\nUnregistering /dead_rospy\ndone\n" in ours.stdout


def test_cleanup_leaves_the_graph_rosnode_leaves(runs: Runs) -> None:
    (ours_nodes, ours_topics), (ref_nodes, ref_topics) = runs.after_cleanup
    assert ours_nodes == ref_nodes == "\n"
    assert ours_topics == ref_topics
    assert "/dead_rospy_chatter" not in ours_topics
