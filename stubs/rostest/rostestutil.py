"""rostest.rostestutil: rostest's log lines and summaries (minros.tools.junitxml)."""

from __future__ import annotations

from typing import Any

from minros.launch.rostestparent import printlog, printlogerr  # noqa: F401
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


def getErrors() -> Any:  # noqa: N802 - rostest's name
    return _errors


def printRostestSummary(result: Any, rostest_results: Any) -> None:  # noqa: N802
    """The summary rostest prints after a run."""
    global _errors
    _errors = result.errors
    print_runner_summary(result, rostest_results, runner_name="ROSTEST")
