"""rostest.rostestutil: rostest's log lines and summaries (minros.tools.junitxml)."""

from __future__ import annotations

import logging
import sys
from typing import Any

from minros.tools.junitxml import create_xml_runner as createXMLRunner  # noqa: F401, N812
from minros.tools.junitxml import (  # noqa: F401
    print_runner_summary,
    rostest_name_from_path,
    test_failure_junit_xml,
    test_success_junit_xml,
)
from minros.tools.junitxml import print_unittest_summary as printSummary  # noqa: F401, N812
from minros.tools.junitxml import xml_results_file as xmlResultsFile  # noqa: F401, N812

_errors: Any = None


def printlog(msg: str, *args: Any) -> None:
    msg = msg % args if args else msg
    logging.getLogger("rostest").info(msg)
    print("[ROSTEST]" + msg)


def printlogerr(msg: str, *args: Any) -> None:
    msg = msg % args if args else msg
    logging.getLogger("rostest").error(msg)
    print("[ROSTEST]" + msg, file=sys.stderr)


def getErrors() -> Any:  # noqa: N802 - rostest's name
    return _errors


def printRostestSummary(result: Any, rostest_results: Any) -> None:  # noqa: N802
    """The summary rostest prints after a run."""
    global _errors
    _errors = result.errors
    print_runner_summary(result, rostest_results, runner_name="ROSTEST")
