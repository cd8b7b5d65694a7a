"""rostest.runner: a .test file as a unittest class (minros.launch.rostestparent)."""

from minros.launch.rostestparent import (  # noqa: F401
    ROS_TEST_RESULTS_DIR,
    ROSTestLaunchParent,
    createUnitTest,
    failDuplicateRunner,
    failRunner,
    getConfig,
    getResults,
    getRostestParents,
    printlog,
    printlogerr,
    rostestRunner,
    setTextMode,
    setUp,
    tearDown,
)
from rostest.rostestutil import (  # noqa: E402, F401
    createXMLRunner,
    printRostestSummary,
    printSummary,
    xmlResultsFile,
)
