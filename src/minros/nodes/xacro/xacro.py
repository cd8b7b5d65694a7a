"""rosrun xacro xacro FILE [name:=value ...]: PyPI's xacro (ROS's own, 2.x) with $(find pkg)
answered by minros's package lookup (through the ament_index_python stand-in), and noetic's
xacro 1.14 behaviour where 2.x differs (minros.nodes.xacro.noetic)."""

from __future__ import annotations

import sys
from typing import List, Optional


def main(argv: Optional[List[str]] = None) -> int:
    try:
        import xacro
    except ImportError:
        print("xacro: the xacro package is not installed (pip install xacro)", file=sys.stderr)
        return 2
    from minros.nodes.xacro.noetic import apply

    apply(xacro)
    if argv is not None:
        sys.argv = list(argv)
    # roslaunch passes __name:= and __log:= to nodes; xacro reads name:=value as its own args
    sys.argv = [a for a in sys.argv if not a.startswith("__")]
    try:
        xacro.main()
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
