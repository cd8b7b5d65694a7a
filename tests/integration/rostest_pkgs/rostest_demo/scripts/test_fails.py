#!/usr/bin/env python
"""A rostest test node whose check fails (the runner must report it and exit 1)."""
import sys
import unittest

import rospy
import rostest


class TestFails(unittest.TestCase):
    def test_wrong(self):
        self.assertEqual(rospy.get_param("/answer"), 41)


if __name__ == "__main__":
    rospy.init_node("test_fails")
    rostest.rosrun("rostest_demo", "test_fails", TestFails, sys.argv)
