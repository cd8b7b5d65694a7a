#!/usr/bin/env python
# ruff: noqa  (verbatim tutorial code: kept as ROS users have it)
# The rospy_tutorials 005_add_two_ints server, as the ROS tutorial "Writing a Simple Service
# and Client (Python)" shows it; run unmodified against minros by
# tests/examples/test_add_two_ints.py.

NAME = 'add_two_ints_server'

# import the AddTwoInts service
from rospy_tutorials.srv import *
import rospy 

def add_two_ints(req):
    print("Returning [%s + %s = %s]" % (req.a, req.b, (req.a + req.b)))
    sum = req.a + req.b
    return AddTwoIntsResponse(sum)

def add_two_ints_server():
    rospy.init_node(NAME)
    s = rospy.Service('add_two_ints', AddTwoInts, add_two_ints)

    # spin() keeps Python from exiting until node is shutdown
    rospy.spin()

if __name__ == "__main__":
    add_two_ints_server()
