"""add_two_ints_client X Y: calls ``add_two_ints`` and prints "X + Y = SUM".

Like the tutorial it does not call init_node: a service client needs no node. Arguments come
through rospy.myargv(), so remapping arguments (``add_two_ints:=/other``) are accepted.
"""

from __future__ import annotations

import random
import sys

import rospy
from rospy_tutorials.srv import AddTwoInts, AddTwoIntsRequest


def add_two_ints_client(x: int, y: int) -> int:
    rospy.wait_for_service("add_two_ints")
    try:
        add_two_ints = rospy.ServiceProxy("add_two_ints", AddTwoInts)
        # both calling styles of the tutorial: positional fields, then an explicit request
        first = add_two_ints(x, y)
        second = add_two_ints.call(AddTwoIntsRequest(x, y))
        if first.sum != second.sum:
            raise rospy.ServiceException(f"the two calls disagree: {first.sum} vs {second.sum}")
        return first.sum
    except rospy.ServiceException as exc:
        print(f"Service call failed: {exc}")
        raise SystemExit(1) from None


def usage() -> str:
    return f"{sys.argv[0]} [x y]"


if __name__ == "__main__":
    argv = rospy.myargv()
    if len(argv) == 1:
        x, y = random.randint(-50000, 50000), random.randint(-50000, 50000)
    elif len(argv) == 3:
        try:
            x, y = int(argv[1]), int(argv[2])
        except ValueError:
            print(usage())
            sys.exit(1)
    else:
        print(usage())
        sys.exit(1)
    print(f"Requesting {x}+{y}")
    print(f"{x} + {y} = {add_two_ints_client(x, y)}")
