"""``minros clean`` / ``rosclean``: how much the ROS log directory holds, and purging it.

    rosclean check                 disk usage of the node logs ($ROS_LOG_DIR or $ROS_HOME/log)
    rosclean purge [-y] [--size MB]   delete them (all, or the oldest until at most MB remain)

The texts and questions are rosclean's. Sizes are measured in Python (no ``du``): ``check``
prints the space the files occupy on disk as ``du -sh`` does, ``--size`` counts their bytes as
``du -sb`` does; deleting is ``shutil.rmtree`` (the question shows rosclean's command).
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import sys
from typing import Callable, List, Optional, Sequence, Tuple

from minros import rosenv

__version__ = "1.7.0"


class CleanupException(Exception):
    """rosclean cannot do what was asked."""


def _get_check_dirs() -> List[Tuple[str, str]]:
    """The folders rosclean looks after that exist, with their labels."""
    dirs = [(str(rosenv.ros_log_dir()), "ROS node logs"),
            (str(rosenv.ros_home() / "rosmake"), "rosmake logs")]
    return [(d, label) for d, label in dirs if os.path.isdir(d)]


def _walk_stats(d: str) -> Tuple[int, int]:
    """``(bytes, allocated bytes)`` of ``d`` and everything below it (links not followed)."""
    size = allocated = 0
    for root, dirs, files in os.walk(d):
        for name in [root] + [os.path.join(root, f) for f in files + [x for x in dirs
                                                                     if os.path.islink(os.path.join(root, x))]]:
            try:
                st = os.lstat(name)
            except OSError:
                continue  # vanished while walking (a node still logging)
            size += st.st_size
            allocated += st.st_blocks * 512
    return size, allocated


def get_disk_usage(d: str) -> int:
    """Bytes in ``d`` (files, links and folders themselves, as ``du -sb``)."""
    if os.path.isdir(d) and not os.path.islink(d):
        return _walk_stats(d)[0]
    try:
        return os.lstat(d).st_size
    except OSError as exc:
        raise CleanupException(f"cannot measure [{d}]: {exc.strerror}") from None


def human_size(size: int) -> str:
    """``du -h``'s spelling of a size: rounded up, one decimal below 10 (``4.0K``, ``12M``)."""
    if size < 1024:
        return str(size)
    for unit in "KMGTPE":
        size_in_unit = size / 1024.0
        size = size_in_unit  # type: ignore[assignment]
        if size_in_unit < 1024 or unit == "E":
            if size_in_unit < 10:
                return f"{math.ceil(size_in_unit * 10) / 10:.1f}{unit}"
            return f"{math.ceil(size_in_unit)}{unit}"
    return str(size)


def get_human_readable_disk_usage(d: str) -> str:
    """The space ``d`` occupies on disk, as ``du -sh`` prints it."""
    return human_size(_walk_stats(d)[1])


def _ask(comment: str, stdin=None, stdout=None) -> bool:  # noqa: ANN001
    """Show ``comment`` and wait for y or n."""
    stdin, stdout = stdin or sys.stdin, stdout or sys.stdout
    stdout.write(f"Okay to perform:\n\n{comment}\n(y/n)?\n")
    stdout.flush()
    while True:
        line = stdin.readline()
        if not line:
            return False  # end of input: nothing was agreed to
        answer = line.strip().lower()
        if answer in ("y", "n"):
            return answer == "y"


def _remove(path: str) -> None:
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path)
    else:
        os.remove(path)


def _sort_file_by_oldest(d: str) -> List[str]:
    """Entries of ``d``, least recently modified first."""
    return sorted(os.listdir(d), key=lambda f: os.path.getmtime(os.path.join(d, f)))


def _rosclean_cmd_check(args: argparse.Namespace) -> None:
    for d, label in _get_check_dirs():
        print(f"{get_human_readable_disk_usage(d)} {label}")


def _rosclean_cmd_purge(args: argparse.Namespace, ask: Callable[[str], bool] = _ask) -> None:
    for d, label in _get_check_dirs():
        if not args.size:
            print(f"Purging {label}.")
            if not args.y:
                print("PLEASE BE CAREFUL TO VERIFY THE COMMAND BELOW!")
                if not ask(f"rm -rf {d}"):
                    continue
            try:
                _remove(d)
            except OSError:
                print("FAILED to execute command", file=sys.stderr)
            continue
        limit = args.size * 1024 * 1024
        log_size = get_disk_usage(d)
        if log_size <= limit:
            print(f"Directory size of {label} is {log_size // 1024 // 1024} MB which is already "
                  f"below the requested threshold of {args.size} MB.")
            continue
        print(f"Purging {label} until directory size is at most {args.size} MB (currently "
              f"{log_size // 1024 // 1024} MB).")
        if not args.y:
            print("PLEASE BE CAREFUL TO VERIFY THE COMMAND BELOW!")
            if not ask(f"Purge some of old logs in {d}"):
                return
        for name in _sort_file_by_oldest(d):
            if log_size <= limit:
                break
            path = os.path.join(d, name)
            log_size -= get_disk_usage(path)
            try:
                _remove(path)
            except OSError:
                print("FAILED to execute command", file=sys.stderr)


def _parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=prog, description="Check and purge ROS log files.")
    sub = parser.add_subparsers(required=True, dest="{check,purge}")
    check = sub.add_parser("check", help="Check usage of log files")
    check.set_defaults(func=_rosclean_cmd_check)
    purge = sub.add_parser("purge", help="Remove log files")
    purge.set_defaults(func=_rosclean_cmd_purge)
    purge.add_argument("-y", action="store_true", default=False,
                       help="CAUTION: automatically confirms all questions to delete files")
    purge.add_argument("--size", action="store", default=None, type=int,
                       help="Maximum total size in MB to keep when deleting old files")
    return parser


def main(argv: Sequence[str], prog: str = "minros clean") -> int:
    args = _parser(prog).parse_args(list(argv))
    try:
        args.func(args)
    except CleanupException as exc:
        print(f"{prog}: {exc}", file=sys.stderr)
        return 1
    return 0


def rosclean_main(argv: Optional[Sequence[str]] = None) -> None:
    """rosclean's entry point: ``argv`` includes the program name."""
    argv = sys.argv if argv is None else argv
    sys.exit(main(list(argv[1:]), prog="rosclean"))


