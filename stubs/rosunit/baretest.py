"""rosunit.baretest's summaries (minros.tools.junitxml)."""

from minros.tools.junitxml import print_runner_summary, print_unittest_summary  # noqa: F401
from rosunit.core import (  # noqa: E402, F401
    create_xml_runner,
    printerrlog,
    printlog,
    printlog_bold,
    rostest_name_from_path,
    xml_results_file,
)

BARE_TIME_LIMIT = 60.0
TIMEOUT_SIGINT = 15.0
TIMEOUT_SIGTERM = 2.0
