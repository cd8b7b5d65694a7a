"""rostest.rostest_main: the rostest command (minros.cli.rostest)."""

from __future__ import annotations

import sys


def rostestmain() -> None:
    """``rostest [pkg] file.test [arg:=value ...]``."""
    from minros.cli.main import run

    sys.exit(run("test", sys.argv[1:], prog="rostest"))
