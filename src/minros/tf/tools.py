"""What the tf command-line tools share: running as a node, frame names, number parsing."""

from __future__ import annotations

import sys
from typing import Callable, List, Optional


class UsageError(Exception):
    """Bad command line: the message is printed, the tool exits with ``status``."""

    def __init__(self, message: str, status: int = 255) -> None:
        super().__init__(message)
        self.status = status


def run_tool(name: str, main: Callable[[], int]) -> int:
    """Run a tool's ``main`` as ROS users expect at a terminal: Ctrl-C ends it quietly, an
    expected failure is one line on stderr, never a traceback."""
    from minros.exceptions import ROSInitException, ROSInterruptException

    try:
        return main()
    except (KeyboardInterrupt, ROSInterruptException):
        return 0
    except UsageError as exc:
        if str(exc):
            sys.stderr.write(f"{exc}\n")
        return exc.status
    except ROSInitException as exc:
        sys.stderr.write(f"{name}: {exc}\n")
        return 1


def tool_args(argv: Optional[List[str]] = None) -> List[str]:
    """The tool's own arguments: argv without the program name and ROS remappings."""
    import minros

    return minros.myargv(list(sys.argv if argv is None else argv))[1:]


def number(text: str, what: str, tool: str) -> float:
    """``text`` as a float, or a UsageError naming the argument (C's atof would read 0)."""
    try:
        return float(text)
    except ValueError:
        raise UsageError(f"{tool}: {what} must be a number, got {text!r}") from None


def cout(value: float) -> str:
    """A double as ``std::cout << value`` prints it by default (6 significant digits)."""
    return f"{value:g}"
