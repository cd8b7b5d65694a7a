"""rostest.rostest_main: the rostest command (minros.cli.rostest)."""

from __future__ import annotations

import os
import socket
import sys
from typing import Optional

from minros.launch.rostestparent import write_bad_filename_failure  # noqa: F401
from minros.roslogging import configure_logging as _configure_logging


def rostestmain() -> None:
    """``rostest [pkg] file.test [arg:=value ...]``."""
    from minros.cli.main import run

    sys.exit(run("test", sys.argv[1:], prog="rostest"))


def configure_logging() -> Optional[str]:
    """rostest's log file, ``rostest-<host>-<pid>.log`` in the log folder; its path."""
    name = _configure_logging("rostest", filename=f"rostest-{socket.gethostname()}-{os.getpid()}.log")
    if name:
        print(f"... logging to {name}")
    return name


from rostest.rostest_parent import ROSTestLaunchParent  # noqa: E402, F401
from rostest.rostestutil import (  # noqa: E402, F401
    createXMLRunner,
    printRostestSummary,
    xmlResultsFile,
)
from rosunit.core import rostest_name_from_path  # noqa: E402, F401

from . import runner  # noqa: E402, F401 - rostest.rostest_main imports it

ROS_TEST_RESULTS_DIR = "ROS_TEST_RESULTS_DIR"
