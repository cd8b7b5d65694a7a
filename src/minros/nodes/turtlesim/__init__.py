"""minros's turtlesim: the simulator node and the tutorial tools of ros_tutorials/turtlesim.

Modules run with ``python -m`` (``rosrun turtlesim <name>`` maps to them): ``turtlesim_node``,
``turtle_teleop_key``, ``draw_square``, ``mimic``. :mod:`minros.nodes.turtlesim.sim` is the simulation
without ROS.
"""

from __future__ import annotations

import sys
from typing import Callable


def run_tool(name: str, main: Callable[[], int]) -> int:
    """Run a tool's ``main`` the way a ROS user expects at the terminal: Ctrl-C ends it quietly,
    a node that could not start says why in one line (no traceback)."""
    from minros.exceptions import ROSInitException, ROSInterruptException

    try:
        return main()
    except (KeyboardInterrupt, ROSInterruptException):
        return 0
    except ROSInitException as exc:
        sys.stderr.write(f"{name}: {exc}\n")
        return 1
