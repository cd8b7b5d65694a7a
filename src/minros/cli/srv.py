"""``minros srv`` (rossrv): show, hash and list service types.

    minros srv show [-r] TYPE   request and response definitions, separated by ---
    minros srv md5 TYPE         md5 sum (of request text + response text)
    minros srv list | package PKG | packages
"""

from __future__ import annotations

from typing import List

from minros.cli import msg as _msg


def main(argv: List[str], prog: str = "minros srv") -> int:
    """Run ``minros srv``; the implementation is shared with ``minros msg``."""
    return _msg.main(argv, prog=prog, kind="srv")


if __name__ == "__main__":  # rosrun rosmsg rossrv
    import sys

    sys.exit(main(sys.argv[1:], prog="rossrv"))
