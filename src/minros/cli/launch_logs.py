"""``roslaunch-logs``: the log folder of the running roscore's run (``$ROS_LOG_DIR/<run_id>``),
as roslaunch.roslaunch_logs prints it."""

from __future__ import annotations

import optparse
import sys
from typing import List, Optional

from minros import rosenv

NAME = "roslaunch-logs"


def get_run_id() -> Optional[str]:
    """The master's ``/run_id`` parameter, or None when no master answers or it has none."""
    from minros.tools.master import Master

    try:
        value = Master("/roslaunch").getParam("/run_id")
    except Exception:  # no master, or no run_id: both mean "no active roscore"
        return None
    return value if isinstance(value, str) and value else None


def main(argv: Optional[List[str]] = None) -> int:
    parser = optparse.OptionParser(usage="usage: %prog", prog=NAME)
    _options, args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if args:
        parser.error(f"{NAME} takes no arguments")
    log_dir = rosenv.ros_log_dir()
    run_id = get_run_id()
    if not run_id:
        print("No active roscore", file=sys.stderr)
        print(log_dir)
        return 2
    print(log_dir / run_id)
    return 0


def logs_main() -> None:
    """roslaunch-logs on ``sys.argv``; exits with its status."""
    sys.exit(main())
