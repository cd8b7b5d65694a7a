"""minros's rostopic, rosservice and rosparam against Debian's on usage: ``-h`` texts, missing
and surplus arguments, unknown options and bad option values.

Debian's three tools parse with optparse (``rostopic type`` and ``delay`` with argparse); the
help text, the "Usage: ..." line, the blank line, the "<tool>: error: ..." line and exit
status 2 must be byte for byte the same. Both tools run once per case with the same arguments
on one Debian rosmaster (a usage error must come before anything asks the master); where
Debian's tool crashes or does something absurd, the deliberate difference is pinned below.
"""

from __future__ import annotations

import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from compare import Outcome, assert_same
from support import (
    PYTHON,
    Proc,
    free_port,
    reference_env,
    require_reference,
    ros_env,
    wait_for_master,
)

# the module's fixture runs about 400 tool processes (bounded by TIMEOUT each): on a loaded
# 2-CPU machine that takes longer than one test's default limit
pytestmark = [pytest.mark.interop, pytest.mark.timeout(900)]

BIN = Path(PYTHON).parent
TIMEOUT = 20.0

TOPIC_CASES = [
    ("rostopic",), ("rostopic", "-h"), ("rostopic", "bogus"),
    ("rostopic", "list", "-h"), ("rostopic", "list", "a", "b"), ("rostopic", "list", "--bogus"),
    ("rostopic", "list", "-p", "-s"), ("rostopic", "list", "-b"), ("rostopic", "list", "-b", "x.bag", "-s"),
    ("rostopic", "list", "-v", "-x"),
    ("rostopic", "info", "-h"), ("rostopic", "info"), ("rostopic", "info", "a", "b"),
    ("rostopic", "info", "--bogus", "/a"),
    ("rostopic", "type", "-h"), ("rostopic", "type"), ("rostopic", "type", "a", "b"),
    ("rostopic", "type", "--bogus", "/a"),
    ("rostopic", "find", "-h"), ("rostopic", "find"), ("rostopic", "find", "a", "b"),
    ("rostopic", "find", "-x", "std_msgs/String"),
    ("rostopic", "echo", "-h"), ("rostopic", "echo"), ("rostopic", "echo", "a", "b"),
    ("rostopic", "echo", "-n", "x", "/a"), ("rostopic", "echo", "-n"), ("rostopic", "echo", "-w", "x", "/a"),
    ("rostopic", "echo", "-w", "1", "/a"), ("rostopic", "echo", "-a", "/a"), ("rostopic", "echo", "--bogus"),
    ("rostopic", "echo", "-b", "x.bag", "--offset"), ("rostopic", "echo", "--filter"),
    ("rostopic", "echo", "-n", "x", "-w", "x", "a", "b"),
    ("rostopic", "hz", "-h"), ("rostopic", "hz"), ("rostopic", "hz", "-w", "x", "/a"),
    ("rostopic", "hz", "--bogus", "/a"), ("rostopic", "hz", "--filter"), ("rostopic", "hz", "-w"),
    ("rostopic", "bw", "-h"), ("rostopic", "bw"), ("rostopic", "bw", "a", "b"),
    ("rostopic", "bw", "-w", "x", "/a"), ("rostopic", "bw", "--bogus", "/a"),
    ("rostopic", "delay", "-h"), ("rostopic", "delay"), ("rostopic", "delay", "a", "b"),
    ("rostopic", "delay", "-w", "x", "/a"), ("rostopic", "delay", "--bogus", "/a"),
    ("rostopic", "pub", "-h"), ("rostopic", "pub"), ("rostopic", "pub", "/a"),
    ("rostopic", "pub", "-r", "x", "/a", "std_msgs/String", "hi"),
    ("rostopic", "pub", "-r", "0", "/a", "std_msgs/String", "hi"),
    ("rostopic", "pub", "-r", "1", "-1", "/a", "std_msgs/String", "hi"),
    ("rostopic", "pub", "-f", "x.yaml", "/a", "std_msgs/String", "hi"),
    ("rostopic", "pub", "--bogus", "/a", "std_msgs/String", "hi"),
    ("rostopic", "pub", "/a", "std_msgs/String", "-r"), ("rostopic", "pub", "--help"),
    ("rostopic", "echo", "-b", "/nonexistent.bag", "/a"), ("rostopic", "list", "-b", "/nonexistent.bag"),
    ("rostopic", "pub", "-r", "-1", "/a", "std_msgs/String", "hi"), ("rostopic", "pub", "/a", "std_msgs/String", "-f"),
    ("rostopic", "echo", "/a", "-h"), ("rostopic", "find", "--help"), ("rostopic", "echo", "-w", "0", "/a"),
]
SERVICE_CASES = [
    ("rosservice",), ("rosservice", "-h"), ("rosservice", "bogus"),
    ("rosservice", "list", "-h"), ("rosservice", "list", "a", "b"), ("rosservice", "list", "--bogus"),
    ("rosservice", "info", "-h"), ("rosservice", "info"), ("rosservice", "info", "a", "b"),
    ("rosservice", "info", "-x", "/a"),
    ("rosservice", "find", "-h"), ("rosservice", "find"), ("rosservice", "find", "a", "b"),
    ("rosservice", "find", "--bogus", "std_srvs/Empty"),
    ("rosservice", "call", "-h"), ("rosservice", "call"), ("rosservice", "call", "-v"),
    ("rosservice", "call", "--bogus", "/a"), ("rosservice", "call", "--wait"), ("rosservice", "call", "/nope", "-h"),
    ("rosservice", "list", "-n", "a", "b"),
] + [("rosservice", command, *args) for command in ("type", "uri", "node", "args")
     for args in (("-h",), (), ("a", "b"), ("--bogus", "/a"))]
PARAM_CASES = [
    ("rosparam",), ("rosparam", "-h"), ("rosparam", "bogus"),
    ("rosparam", "get", "-h"), ("rosparam", "get"), ("rosparam", "get", "a", "b"), ("rosparam", "get", "--bogus", "/a"),
    ("rosparam", "dump", "-h"), ("rosparam", "dump", "a", "b", "c"), ("rosparam", "dump", "--bogus"),
    ("rosparam", "set", "-h"), ("rosparam", "set"), ("rosparam", "set", "/a"), ("rosparam", "set", "/a", "1", "2"),
    ("rosparam", "set", "/a", "-t"), ("rosparam", "set", "-t", "-v", "/a"), ("rosparam", "set", "-t", "f", "-b", "g", "/a"),
    ("rosparam", "set", "--bogus", "/a", "1"), ("rosparam", "set", "-t", "/nonexistent.txt", "/a"),
    ("rosparam", "load", "-h"), ("rosparam", "load"), ("rosparam", "load", "a", "b", "c"), ("rosparam", "load", "--bogus", "a"),
    ("rosparam", "delete", "-h"), ("rosparam", "delete"), ("rosparam", "delete", "a", "b"), ("rosparam", "delete", "-x", "a"),
    ("rosparam", "list", "-h"), ("rosparam", "list", "a", "b"), ("rosparam", "list", "--bogus"),
    ("rosparam", "get", "--help"), ("rosparam", "set", "-v"), ("rosparam", "get", "-p"),
    ("rosparam", "dump", "-v", "a", "b", "c"), ("rosparam", "load", "-v"), ("rosparam", "delete", "--help"),
]
CASES = TOPIC_CASES + SERVICE_CASES + PARAM_CASES
#: usage errors come before the master is asked: the same texts when no master runs
NO_MASTER_CASES = [
    ("rostopic", "pub", "-r", "x", "/a", "std_msgs/String", "hi"), ("rostopic", "echo", "-n", "x", "/a"),
    ("rostopic", "hz", "-w", "x", "/a"), ("rostopic", "delay", "-w", "x", "/a"), ("rostopic", "info"),
    ("rosservice", "call"), ("rosservice", "info", "a", "b"), ("rosparam", "set", "/a"), ("rosparam", "get"),
]
#: where minros deliberately differs (see the tests at the end)
ABSURD_LIST = ("rosparam", "list", "a", "b", "c")
BINFILE_CRASH = ("rosparam", "set", "-b", "/nonexistent.bin", "/a")
NEGATIVE_CALL = ("rosservice", "call", "/nope", "-1")
NEGATIVE_SET = ("rosparam", "set", "/neg", "-.5")
YAML_ERROR = ("rostopic", "pub", "/a", "std_msgs/String", "{a: [")
DELIBERATE = [ABSURD_LIST, BINFILE_CRASH, NEGATIVE_CALL, NEGATIVE_SET, YAML_ERROR]


def _run(argv: list, env: dict) -> Outcome:
    try:
        done = subprocess.run(argv, env=env, input="", capture_output=True, text=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired as exc:
        raise AssertionError(f"{argv} did not finish within {TIMEOUT}s: {exc.stdout}{exc.stderr}") from None
    return Outcome(argv, done.returncode, done.stdout, done.stderr)


def _both(env: dict, cases: list) -> dict:
    """case -> (minros's outcome, Debian's outcome), each tool run once per case."""
    renv = reference_env(env)

    def both(case: tuple) -> tuple:
        tool, *args = case
        return _run([str(BIN / tool), *args], env), _run([f"/usr/bin/{tool}", *args], renv)

    with ThreadPoolExecutor(4) as pool:
        return dict(zip(cases, pool.map(both, cases)))


class Runs:
    cases: dict
    no_master: dict
    negative_set: Outcome  # Debian's rosparam get of what minros's 'set /neg -.5' stored


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> Runs:
    """Every case once with minros's tool and once with Debian's, on one Debian rosmaster."""
    require_reference()
    home = tmp_path_factory.mktemp("usage_parity") / "ros_home"
    (home / "log").mkdir(parents=True)
    result = Runs()
    result.no_master = _both(ros_env(free_port(), home), NO_MASTER_CASES)
    port = free_port()
    env = ros_env(port, home)
    master = Proc(["/usr/bin/rosmaster", "--core", "-p", str(port)], reference_env(env))
    try:
        wait_for_master(port)
        result.cases = _both(env, CASES + DELIBERATE)
        result.negative_set = _run(["/usr/bin/rosparam", "get", "/neg"], reference_env(env))
    finally:
        master.stop()
    return result


def _ids(cases: list) -> list:
    return [" ".join(c) for c in cases]


@pytest.mark.parametrize("case", CASES, ids=_ids(CASES))
def test_usage_like_debian(runs: Runs, case: tuple) -> None:
    ours, reference = runs.cases[case]
    assert_same(ours, reference, compare_stderr=True)


@pytest.mark.parametrize("case", NO_MASTER_CASES, ids=_ids(NO_MASTER_CASES))
def test_usage_errors_come_before_the_master(runs: Runs, case: tuple) -> None:
    ours, reference = runs.no_master[case]
    assert_same(ours, reference, compare_stderr=True)
    assert ours.status == 2 and "Unable to communicate" not in ours.stderr, ours


def test_texts_are_optparse_texts(runs: Runs) -> None:
    """The comparison is not vacuous: these are Debian's optparse/argparse layouts."""
    ours, reference = runs.cases[("rostopic", "echo", "-n", "x", "/a")]
    assert reference.stderr == ("Usage: rostopic echo [options] /topic\n\n"
                                "rostopic: error: COUNT must be an integer\n")
    assert (ours.stderr, ours.status) == (reference.stderr, reference.status) == (reference.stderr, 2)
    ours, reference = runs.cases[("rosparam", "get", "-h")]
    assert reference.stdout.startswith("Usage: rosparam get [options] parameter\n\nOptions:\n")
    assert ours.stdout == reference.stdout and ours.status == 0
    ours, reference = runs.cases[("rostopic", "delay", "-w", "x", "/a")]  # argparse in rostopic
    assert reference.stderr.endswith("rostopic: error: argument -w/--window: invalid int value: 'x'\n")
    assert ours.stderr == reference.stderr
    ours, reference = runs.cases[("rostopic", "-h")]
    assert ours.status == reference.status == 64 and ours.stdout == reference.stdout


# ---------------------------------------------------------------------------------------------
# deliberate differences

def test_too_many_namespaces_for_list_is_an_error(runs: Runs) -> None:
    """rosparam list objects to exactly two namespaces but silently lists the whole server for
    three or more (its check is ``len(args) == 2``), status 0; minros says "too many arguments" for any
    surplus, with the text rosparam uses for two."""
    ours, reference = runs.cases[ABSURD_LIST]
    assert reference.status == 0 and reference.stderr == ""
    two = runs.cases[("rosparam", "list", "a", "b")][1]
    assert (ours.status, ours.stdout, ours.stderr) == (2, "", two.stderr)
    assert two.stderr.endswith("rosparam: error: too many arguments\n")


def test_missing_binfile_is_one_line(runs: Runs) -> None:
    """rosparam set -b with a file that is not there dies with a traceback; minros prints one
    line with the same exit status."""
    ours, reference = runs.cases[BINFILE_CRASH]
    assert "Traceback" in reference.stderr and reference.status == 1
    assert (ours.status, ours.stdout) == (1, "")
    assert ours.stderr == "ERROR: cannot read [/nonexistent.bin]: No such file or directory\n"


def test_negative_numbers_are_values(runs: Runs) -> None:
    """optparse reads '-1' as an option (rosservice call) and '-.5' too (rosparam set only
    spares '-<digit>'); minros takes negative numbers as the values they are."""
    ours, reference = runs.cases[NEGATIVE_CALL]
    assert reference.stderr.endswith("rosservice: error: no such option: -1\n")
    assert (ours.status, ours.stderr) == (2, "ERROR: Service [/nope] is not available.\n")
    ours, reference = runs.cases[NEGATIVE_SET]
    assert reference.stderr.endswith("rosparam: error: no such option: -.\n") and reference.status == 2
    assert (ours.status, ours.stdout, ours.stderr) == (0, "", "")
    # stored as the value (PyYAML reads '-.5' as a string), read back by Debian's rosparam
    assert runs.negative_set.stdout == "-.5\n"


def test_yaml_argument_error_is_one_line(runs: Runs) -> None:
    """rostopic pub prints PyYAML's multi-line message in its usage error; minros keeps the
    error on one line (CLI rule) with the same words, usage line and status."""
    ours, reference = runs.cases[YAML_ERROR]
    assert ours.status == reference.status == 2
    head = "Usage: rostopic pub /topic type [args...]\n\n"
    assert ours.stderr.startswith(head) and reference.stderr.startswith(head)
    assert len(reference.stderr[len(head):].splitlines()) > 1
    assert len(ours.stderr[len(head):].splitlines()) == 1
    assert ours.stderr[len(head):].startswith("rostopic: error: Argument error: while parsing a flow node")
    assert ours.stderr.split() == reference.stderr.split()
