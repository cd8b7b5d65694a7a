"""``minros run`` / ``rosrun PACKAGE EXECUTABLE [ARGS]``: run a program of a package.

Same search, messages and exit codes as the rosrun script: the package's executables at any
depth (executable bit required), remapping arguments passed through untouched. The process is
replaced by the program (exec), so Ctrl-C and exit status reach it directly. Python scripts
run under minros's interpreter, and its folder is put on PATH for the programs they start.
"""

from __future__ import annotations

import os
import shlex
import sys
from typing import List

USAGE = """Usage: rosrun [--prefix cmd] [--debug] PACKAGE EXECUTABLE [ARGS]
  rosrun will locate PACKAGE and try to find
  an executable named EXECUTABLE in the PACKAGE tree.
  If it finds it, it will run it with ARGS."""


def main(argv: List[str], prog: str | None = None) -> int:
    from minros.workspace.nodes import ExecutableError, child_environment, resolve_executable

    args = list(argv)
    prefix: List[str] = []
    debug = False
    while args:
        if args[0] in ("-h", "--help"):
            print(USAGE)
            return 0
        if args[0] in ("-p", "--prefix") and len(args) >= 2:
            prefix = shlex.split(args[1])
            del args[:2]
        elif args[0] in ("-d", "--debug"):
            debug = True
            del args[0]
        else:
            break
    if len(args) < 2:
        print(USAGE)
        return 0
    pkg, executable, rest = args[0], args[1], args[2:]
    try:
        command = resolve_executable(pkg, executable)
    except ExecutableError as exc:
        # rosrun echoes its own lines to stdout; rospack's error goes to stderr
        stream = sys.stderr if exc.exit_code == 2 else sys.stdout
        for line in exc.lines:
            print(line, file=stream)
        return exc.exit_code
    full = prefix + command + rest
    if debug:
        print("[rosrun] Running", " ".join(full))
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        os.execvpe(full[0], full, child_environment())
    except OSError as exc:
        print(f"[rosrun] cannot run {full[0]}: {exc.strerror}", file=sys.stderr)
        return 126
    return 0  # not reached
