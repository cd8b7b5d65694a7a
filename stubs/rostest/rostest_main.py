"""rostest.rostest_main: the rostest command (minros.cli.rostest)."""

from __future__ import annotations

import sys


def rostestmain() -> None:
    """``rostest [pkg] file.test [arg:=value ...]``."""
    from minros.cli.main import run

    sys.exit(run("test", sys.argv[1:], prog="rostest"))

from rostest.rostestutil import printRostestSummary  # noqa: E402, F401
from rosunit.core import rostest_name_from_path  # noqa: E402, F401

ROS_TEST_RESULTS_DIR = "ROS_TEST_RESULTS_DIR"
