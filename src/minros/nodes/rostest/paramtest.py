"""paramtest: a parameter is set (to a value, if the test names one) within a wait.

Parameters (private): ``param_name_target`` (the parameter to look for),
``param_value_expected`` (compared when given), ``test_duration`` (must be positive, 5),
``wait_time`` (wall seconds to wait for the parameter, 20).
"""

from __future__ import annotations

import sys
import time
import unittest
from typing import Any, List, Optional

import minros
from minros.nodes.rostest._common import required, run

POLL = 0.1  # seconds between two looks: the parameter server has no change events


class ParamTest(unittest.TestCase):
    def test_param(self) -> None:
        target = str(required(self, "~param_name_target"))
        expected = minros.get_param("~param_value_expected", None)
        duration = float(minros.get_param("~test_duration", 5))
        wait_time = float(minros.get_param("~wait_time", 20))
        print(f"Parameter: {target} Test Duration: {duration}")
        self.assertTrue(duration > 0.0, "bad parameter (test_duration)")
        self.assertTrue(target, "bad parameter (param_name_target)")
        print("Waiting for parameters")
        value: Any = None
        deadline = time.monotonic() + wait_time
        while value is None and time.monotonic() < deadline:
            try:
                value = minros.get_param(target)
            except KeyError:
                time.sleep(POLL)
        if expected:
            self.assertEqual(expected, value)
        else:
            self.assertIsNotNone(value, f"parameter [{target}] is not set after {wait_time:g} s")


def main(argv: Optional[List[str]] = None) -> int:
    return run("paramtest", ParamTest, argv)


if __name__ == "__main__":
    sys.exit(main())
