"""Small pieces every command-line tool shares: error type, argument parsers, dispatch."""

from __future__ import annotations

import argparse
import optparse
import os
import sys
from typing import Any, Callable, Dict, List

from minros import names


class ToolError(Exception):
    """An expected failure: printed as ``ERROR: <text>`` (one line) with ``status``."""

    def __init__(self, text: str, status: int = 1, prefix: str = "ERROR: ") -> None:
        super().__init__(text)
        self.text = text
        self.status = status
        self.prefix = prefix


class ArgParser(argparse.ArgumentParser):
    """argparse that reports errors like optparse tools do, through :class:`ToolError`-free exit 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        self.exit(2, f"{self.prog}: error: {message}\n")


def parser(prog: str, usage: str | None = None, description: str | None = None) -> ArgParser:
    return ArgParser(prog=prog, usage=usage, description=description)


def option_parser(prog: str, usage: str = "") -> optparse.OptionParser:
    """The optparse parser Debian's rostopic, rosservice, rosparam and rosnode build: with it
    the ``-h`` text and the usage errors ("Usage: <tool> <command>...", a blank line,
    "<tool>: error: ...", exit status 2) come out byte for byte the same.

    ``prog`` is "<tool> <command>"; the usage line names both, the error line only the tool.
    Add options with ``add_option(..., default=...)``; optparse defaults are ``None``."""
    tool = prog.rsplit(" ", 1)[0] if " " in prog else prog
    return optparse.OptionParser(usage=f"usage: {prog}{usage}", prog=tool)


def strip_ros_args(argv: List[str]) -> List[str]:
    """Remove remapping arguments (``__master:=...``) as rospy.myargv does."""
    return names.strip_remapping_args(argv)


def resolve(tool: str, name: str) -> str:
    return names.script_resolve_name(tool, name)


def dispatch(argv: List[str], prog: str, commands: Dict[str, Callable[[List[str], str], int]],
             usage: str, usage_status: int = 0) -> int:
    """Run ``commands[argv[0]]``; print ``usage`` for none/unknown/--help."""
    argv = strip_ros_args(list(argv))
    if argv and argv[0] in ("-h", "--help"):
        print(usage)
        return 0
    if not argv or argv[0] not in commands:
        # the ROS tools print their usage on stdout, with EX_USAGE (64) or 0 (rosparam)
        print(usage)
        return usage_status
    command = argv[0]
    return int(commands[command](argv[1:], f"{prog} {command}") or 0)


def flush_stdout() -> None:
    try:
        sys.stdout.flush()
    except (BrokenPipeError, ValueError):
        pass


def explained(exc: BaseException) -> str | None:
    """The one line the XML-RPC client wrote for the failure behind ``exc`` (a request over
    the master's size limit, a host outside its ROS_ALLOWED_HOSTS, a reply that is not
    XML-RPC), or None when it is a plain network failure (master not running)."""
    from minros.wire.xmlrpc import CallError

    cause = exc if isinstance(exc, CallError) else exc.__cause__
    return str(cause) if isinstance(cause, CallError) else None


def run_tool(fn: Callable[[], int], io_message: str = "Unable to communicate with master!",
             io_status: int = 1) -> int:
    """Run ``fn``; translate expected failures to one line on stderr and an exit status."""
    from minros.tools.master import MasterError, MasterFailure, MasterIOError
    from minros.wire.xmlrpc import CallError

    try:
        return int(fn() or 0)
    except ToolError as exc:
        flush_stdout()
        print(f"{exc.prefix}{exc.text}", file=sys.stderr)
        return exc.status
    except MasterIOError as exc:
        flush_stdout()
        print(f"ERROR: {explained(exc) or io_message}", file=sys.stderr)
        return io_status
    except CallError as exc:  # a call to a node (or through the client library) that failed
        flush_stdout()
        print(f"ERROR: {exc}", file=sys.stderr)
        return io_status
    except (MasterError, MasterFailure) as exc:
        flush_stdout()
        print(f"ERROR: {exc}", file=sys.stderr)
        return io_status
    except KeyboardInterrupt:
        return 0
    except BrokenPipeError:
        try:
            sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - swallow the final flush
        except OSError:
            pass
        return 0


def library_call(fn: Callable[[], Any], error: type, io_error: type,
                 io_message: str = "Unable to communicate with master!") -> Any:
    """Run a tool's function for a Python caller: the tool's expected failures become the
    exceptions its Python API documents (``error``; ``io_error`` when the master cannot be
    reached) instead of an exit status."""
    from minros.tools.master import MasterError, MasterFailure, MasterIOError
    from minros.wire.xmlrpc import CallError

    try:
        return fn()
    except ToolError as exc:
        raise error(exc.text) from None
    except MasterIOError as exc:
        raise io_error(explained(exc) or io_message) from None
    except CallError as exc:
        raise io_error(str(exc)) from None
    except (MasterError, MasterFailure) as exc:
        raise error(str(exc)) from None
