"""add_two_ints_server: offers ``add_two_ints`` (rospy_tutorials/AddTwoInts), answering a + b."""

from __future__ import annotations

import rospy
from rospy_tutorials.srv import AddTwoInts, AddTwoIntsRequest, AddTwoIntsResponse


def handle_add_two_ints(req: AddTwoIntsRequest) -> AddTwoIntsResponse:
    total = req.a + req.b
    print(f"Returning [{req.a} + {req.b} = {total}]", flush=True)
    return AddTwoIntsResponse(total)


def add_two_ints_server() -> None:
    rospy.init_node("add_two_ints_server")
    rospy.Service("add_two_ints", AddTwoInts, handle_add_two_ints)
    print("Ready to add Two Ints.", flush=True)
    rospy.spin()


if __name__ == "__main__":
    add_two_ints_server()
