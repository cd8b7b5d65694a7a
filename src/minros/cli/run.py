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
from pathlib import Path
from typing import List

USAGE = """Usage: rosrun [--prefix cmd] [--debug] PACKAGE EXECUTABLE [ARGS]
  rosrun will locate PACKAGE and try to find
  an executable named EXECUTABLE in the PACKAGE tree.
  If it finds it, it will run it with ARGS."""


def _pick(candidates: List[Path]) -> Path | None:
    """Ask for one of several executables by number; None on end of input."""
    while True:
        try:
            answer = input("#? ")
        except EOFError:
            print()
            return None
        if answer.strip().isdigit() and 1 <= int(answer) <= len(candidates):
            return candidates[int(answer) - 1]
        for i, path in enumerate(candidates, 1):
            print(f"{i}) {path}", file=sys.stderr)


def main(argv: List[str], prog: str | None = None) -> int:
    from minros.workspace.executables import (
        ExecutableError,
        child_environment,
        command_for,
        resolve_executable,
    )

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
        if not exc.candidates:
            return exc.exit_code
        chosen = _pick(exc.candidates)  # like the bash `select` of rosrun
        if chosen is None:
            return 1
        command = command_for(chosen)
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
