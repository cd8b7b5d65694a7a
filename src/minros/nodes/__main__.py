"""``python -m minros.nodes MODULE [ARGS]``: run a built-in node's module as ``__main__``.

rosrun and roslaunch start every program minros ships this way (``executables.resolve_executable``),
so that a node that cannot start, above all on a ROS_MASTER_URI that is not a URI
(``localhost:11311``), says so in one line naming the value and its fix, with no traceback: the
rospy tutorials are written as ROS's are, without a handler of their own, and a handler in each
node is one that some node lacks.
"""

from __future__ import annotations

import runpy
import sys

from minros.exceptions import ROSInitException


def main() -> int:
    if len(sys.argv) < 2:
        sys.stderr.write("usage: python -m minros.nodes MODULE [ARGS]\n")
        return 2
    module = sys.argv[1]
    del sys.argv[1]  # the node sees its own arguments (runpy sets argv[0] to its file)
    try:
        runpy.run_module(module, run_name="__main__", alter_sys=True)
    except ROSInitException as exc:  # init_node's: a bad master URI, a bad node name
        sys.stdout.flush()
        sys.stderr.write(f"{module.rpartition('.')[2]}: {exc}\n")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
