"""rosunit.rosunit_main: the rosunit command (minros.launch.baretest)."""

from __future__ import annotations

import sys

from minros.launch.baretest import rosunit_main as _main
from rosunit.baretest import BareTestCase, print_runner_summary  # noqa: E402, F401
from rosunit.core import create_xml_runner, xml_results_file  # noqa: E402, F401
from rosunit.junitxml import Result, print_summary  # noqa: E402, F401

from . import pmon  # noqa: F401 - rosunit.rosunit_main imports it


def rosunitmain() -> None:
    """``rosunit [options] <file> [test args...]``."""
    sys.exit(_main(sys.argv[1:]))
