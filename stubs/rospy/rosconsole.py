"""rospy.rosconsole: the ``rosconsole`` command (list, get, set, echo) over minros's
(minros.cli.console)."""

from __future__ import annotations

import sys
from typing import Any, List, Optional

from minros.cli import console as _console
from minros.cli.console import (  # noqa: F401
    NAME,
    LoggerLevelServiceCaller,
    RosConsoleEcho,
    ROSConsoleException,
    error,
)


def main(argv: Optional[List[str]] = None) -> None:
    """rosconsole with ``argv`` (``sys.argv``: the program name first); exits non-zero on error."""
    argv = sys.argv if argv is None else argv
    status = _console.main(list(argv[1:]))
    if status:
        sys.exit(status)


def __getattr__(name: str) -> Any:
    if name == "Log":  # rosgraph_msgs/Log, built on first use
        from minros.msgs import get_message_class

        return get_message_class("rosgraph_msgs/Log")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
