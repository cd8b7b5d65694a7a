"""What the tf command-line tools share: running as a node, frame names, number parsing."""

from __future__ import annotations

import sys
from typing import Callable, Collection, List, Optional, Tuple


class UsageError(Exception):
    """The tool ends at its command line: the message (if any) is printed, the tool exits with
    ``status``."""

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


def command_line(argv: Optional[List[str]], usage: str, counts: Collection[int],
                 error: str = "") -> Tuple[List[str], List[str]]:
    """(the whole argv, the tool's own arguments) of a tool whose ``usage`` text is printed on
    stdout for ``-h``/``--help`` (the tool then ends with status 0) and for a number of
    arguments not in ``counts`` (it then fails with ``error``, status 255)."""
    full_argv = list(sys.argv if argv is None else argv)
    args = tool_args(full_argv)
    if args and args[0] in ("-h", "--help"):
        sys.stdout.write(usage)
        raise UsageError("", 0)
    if len(args) not in counts:
        sys.stdout.write(usage)
        raise UsageError(error)
    return full_argv, args


def number(text: str, what: str, tool: str) -> float:
    """``text`` as a float, or a UsageError naming the argument (C's atof would read 0)."""
    try:
        return float(text)
    except ValueError:
        raise UsageError(f"{tool}: {what} must be a number, got {text!r}") from None


def cout(value: float) -> str:
    """A double as ``std::cout << value`` prints it by default (6 significant digits)."""
    return f"{value:g}"
