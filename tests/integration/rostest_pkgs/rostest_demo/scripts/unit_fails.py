#!/usr/bin/env python3
"""A rosunit test program without a ROS graph: one check passes, one fails (--sleep: hangs)."""
import sys
import time
import unittest


class Checks(unittest.TestCase):
    def test_right(self):
        self.assertEqual(2 + 2, 4)

    def test_wrong(self):
        self.assertEqual(2 + 2, 5)


if __name__ == "__main__":
    if "--sleep" in sys.argv:
        time.sleep(30)
    import rosunit

    rosunit.unitrun("rostest_demo", "unit_fails", Checks)
