"""Stand-in for rosunit's Python API: unittest results as JUnit XML (minros.tools.testing)."""

from __future__ import annotations

import sys
from typing import Any, Sequence

from minros.tools.junitxml import (  # noqa: F401
    create_xml_runner,
    print_summary,
    rostest_name_from_path,
    xml_results_file,
)
from minros.tools.testing import XML_OUTPUT_FLAG  # noqa: F401


def unitrun(package: str, test_name: str, test: Any, sysargs: Sequence[str] | None = None,
            coverage_packages: Any = None) -> None:
    """Run a unittest TestCase (or dotted name); exits 1 when a test failed."""
    from minros.tools.testing import run_suite

    if not run_suite(package, test_name, test, sysargs).wasSuccessful():
        sys.exit(1)

from rosunit.baretest import print_runner_summary, print_unittest_summary  # noqa: E402, F401
