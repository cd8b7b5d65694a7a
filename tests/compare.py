"""Compare a tool's output with a reference tool's output on the same ROS graph.

Only what legitimately differs between two runs is masked: port numbers, process ids,
anonymous-name suffixes, wall-clock times and durations, sequence numbers. Everything else
(spelling, spacing, order, blank lines) must match. Used by the oracle tests that run
minros's tools and Debian's rostopic/rosnode/rosparam/rosservice side by side.
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass
from typing import Iterable, List, Pattern, Sequence, Tuple

#: (pattern, replacement), applied in order
DEFAULT_RULES: List[Tuple[Pattern[str], str]] = [
    # anonymous node names: rospy name_<pid>_<millis>, rosgraph name_<host>_<pid>_<random>
    (re.compile(r"(/[A-Za-z][\w]*?)_\d+_\d{10,}"), r"\1_ANON"),
    # ports in URIs and host:port pairs
    (re.compile(r"((?:https?|rosrpc)://[^/:\s]+):\d+"), r"\1:PORT"),
    (re.compile(r"(localhost|\d+\.\d+\.\d+\.\d+):\d+"), r"\1:PORT"),
    (re.compile(r"port \d+"), "port PORT"),
    (re.compile(r"on socket \d+"), "on socket N"),
    (re.compile(r"\(\d+ - "), "(PORT - "),
    # process ids
    (re.compile(r"^Pid: \d+$", re.M), "Pid: PID"),
    # times: header stamps in YAML, durations in ms, nanosecond stamps in CSV
    (re.compile(r"^(\s*secs: )\d+$", re.M), r"\1S"),
    (re.compile(r"^(\s*nsecs: )\s*\d+$", re.M), r"\1NS"),
    (re.compile(r"^(\s*seq: )\d+$", re.M), r"\1SEQ"),
    (re.compile(r"time=[\d.]+ms"), "time=Tms"),
    (re.compile(r"average: [\d.]+ms"), "average: Tms"),
    (re.compile(r"^\d{15,},", re.M), "STAMP,"),
]


def normalize(text: str, rules: Sequence[Tuple[Pattern[str], str]] = DEFAULT_RULES,
              extra: Iterable[Tuple[str, str]] = ()) -> str:
    """``text`` with the volatile parts masked (``extra``: more (regex, replacement) pairs)."""
    for pattern, repl in rules:
        text = pattern.sub(repl, text)
    for pattern_text, repl in extra:
        text = re.sub(pattern_text, repl, text, flags=re.M)
    return text


@dataclass
class Outcome:
    """What one tool run produced."""

    argv: List[str]
    status: int
    stdout: str
    stderr: str


def differences(ours: Outcome, reference: Outcome, compare_stderr: bool = False,
                extra: Iterable[Tuple[str, str]] = ()) -> List[str]:
    """Human-readable differences (empty when the outputs agree after normalization)."""
    extra = list(extra)
    problems: List[str] = []
    if ours.status != reference.status:
        problems.append(f"exit status {ours.status} != reference {reference.status}")
    a, b = normalize(ours.stdout, extra=extra), normalize(reference.stdout, extra=extra)
    if a != b:
        diff = difflib.unified_diff(b.splitlines(), a.splitlines(), "reference", "minros", lineterm="")
        problems.append("stdout differs:\n" + "\n".join(diff))
    if compare_stderr:
        a, b = normalize(ours.stderr, extra=extra), normalize(reference.stderr, extra=extra)
        if a != b:
            diff = difflib.unified_diff(b.splitlines(), a.splitlines(), "reference", "minros", lineterm="")
            problems.append("stderr differs:\n" + "\n".join(diff))
    return problems


def assert_same(ours: Outcome, reference: Outcome, compare_stderr: bool = False,
                extra: Iterable[Tuple[str, str]] = ()) -> None:
    problems = differences(ours, reference, compare_stderr, extra)
    if problems:
        raise AssertionError(
            f"minros {' '.join(ours.argv)} disagrees with {' '.join(reference.argv)}:\n"
            + "\n".join(problems)
            + f"\n--- minros stdout ---\n{ours.stdout}--- minros stderr ---\n{ours.stderr}"
            + f"--- reference stdout ---\n{reference.stdout}--- reference stderr ---\n{reference.stderr}")
