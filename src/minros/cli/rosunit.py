"""``rosunit [options] <file> [test args...]``: run a test program, results as JUnit XML.

The program (a Python unittest file calling ``rosunit.unitrun``, or any executable taking
``--gtest_output=xml:FILE``) runs as one case of a unittest suite (minros.launch.baretest);
its results go to ``$ROS_TEST_RESULTS_DIR/<pkg>/rosunit-<name>.xml``, the wrapper's to
``rostest-<name>.xml``, and rosunit's summary is printed.
"""

from __future__ import annotations

from typing import List


def main(argv: List[str], prog: str = "rosunit") -> int:
    from minros.launch.baretest import rosunit_main

    return rosunit_main(argv, prog=prog)
