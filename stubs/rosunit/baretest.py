"""rosunit.baretest: test programs run as unittest cases, and the summaries
(minros.launch.baretest, minros.tools.junitxml)."""

from minros.launch.baretest import (  # noqa: F401
    BARE_TIME_LIMIT,
    TIMEOUT_SIGINT,
    TIMEOUT_SIGTERM,
    BareTestCase,
    LocalProcess,
    TestTimeoutException,
)
from minros.tools.junitxml import print_runner_summary, print_unittest_summary  # noqa: F401
from rosunit.core import (  # noqa: E402, F401
    create_xml_runner,
    printerrlog,
    printlog,
    printlog_bold,
    rostest_name_from_path,
    xml_results_file,
)
