#!/usr/bin/env python
"""A rostest test node: unittest checks against the counter node's topic and parameters."""
import sys
import unittest

import rospy
import rostest
from std_msgs.msg import Int32


class TestCounter(unittest.TestCase):
    def test_counts_up_from_start(self):
        first = rospy.wait_for_message("/counter/out", Int32, timeout=10)
        second = rospy.wait_for_message("/counter/out", Int32, timeout=10)
        self.assertGreaterEqual(first.data, rospy.get_param("/counter/start"))
        self.assertGreater(second.data, first.data)

    def test_parameter_from_launch_file(self):
        self.assertEqual(rospy.get_param("~expected_start"), 100)

    def test_graph(self):
        self.assertTrue(rostest.is_publisher("/counter/out", "/counter"))


if __name__ == "__main__":
    rospy.init_node("test_counter")
    rostest.rosrun("rostest_demo", "test_counter", TestCounter, sys.argv)
