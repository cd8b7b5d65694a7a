"""Bounded log files, rotated as ROS rotates them, with lines from remote input truncated.

ROS's sizes: rospy's logging configuration (``/etc/ros/python_logging.conf``) rotates a node's
log, master.log and roslaunch's own log at 50,000,000 bytes keeping 4 old files; the C++ rosout
node rotates rosout.log at 100 MiB keeping 10. A log line may carry what a remote peer chose (a
caller_id, a parameter name, a /rosout message), so every line written here is cut at
:data:`MAX_LINE` characters: a client cannot decide how fast the disk fills. The console
output of processes roslaunch starts (``output="log"``), which ROS lets grow, is rotated with
the node log's sizes by :func:`rotate_copy_truncate`.
"""

from __future__ import annotations

import logging
import logging.handlers
import os
import shutil
import threading
from pathlib import Path
from typing import TextIO, Union

__all__ = [
    "MAX_LINE",
    "NODE_LOG_BACKUPS",
    "NODE_LOG_MAX_BYTES",
    "ROSOUT_BACKUPS",
    "ROSOUT_MAX_BYTES",
    "RotatingLog",
    "TruncatingFormatter",
    "rotate_copy_truncate",
    "rotating_handler",
    "truncate",
]

#: rospy's RotatingFileHandler arguments (python_logging.conf): node logs, master.log
NODE_LOG_MAX_BYTES = 50_000_000
NODE_LOG_BACKUPS = 4
#: the C++ rosout node's defaults for rosout.log
ROSOUT_MAX_BYTES = 100 * 1024 * 1024
ROSOUT_BACKUPS = 10
#: characters of one log line; the rest is replaced by a note of how much was cut
MAX_LINE = 8192

PathLike = Union[str, "os.PathLike[str]"]


def truncate(text: str, limit: int = MAX_LINE) -> str:
    """``text`` cut at ``limit`` characters, saying how many were left out."""
    if len(text) <= limit:
        return text
    return f"{text[:limit]}... [{len(text) - limit} more characters]"


class TruncatingFormatter(logging.Formatter):
    """A formatter whose lines (traceback included) are at most MAX_LINE characters."""

    def __init__(self, fmt: str | None = None, limit: int = MAX_LINE) -> None:
        super().__init__(fmt)
        self.limit = limit

    def format(self, record: logging.LogRecord) -> str:
        return truncate(super().format(record), self.limit)


def rotating_handler(path: PathLike, fmt: str, max_bytes: int = NODE_LOG_MAX_BYTES,
                     backups: int = NODE_LOG_BACKUPS) -> logging.Handler:
    """rospy's file handler: ``path`` rotated at ``max_bytes`` keeping ``backups`` old files,
    lines truncated. OSError when the file cannot be opened."""
    handler = logging.handlers.RotatingFileHandler(path, "a", max_bytes, backups, encoding="utf-8")
    handler.setFormatter(TruncatingFormatter(fmt))
    return handler


def _shift(path: Path, backups: int) -> None:
    """``path.(n-1)`` -> ``path.n`` ... ``path.1`` -> ``path.2``, the oldest dropped."""
    for i in range(backups - 1, 0, -1):
        older = path.with_name(f"{path.name}.{i}")
        if older.exists():
            os.replace(older, path.with_name(f"{path.name}.{i + 1}"))


class RotatingLog:
    """An append-only text log rotated by size (``rosout.log`` -> ``rosout.log.1`` ...), each
    line truncated to MAX_LINE characters. Thread-safe."""

    def __init__(self, path: Path, max_size: int = ROSOUT_MAX_BYTES,
                 backups: int = ROSOUT_BACKUPS, limit: int = MAX_LINE) -> None:
        self.path = path
        self.max_size = max_size
        self.backups = backups
        self.limit = limit
        self._lock = threading.Lock()
        path.parent.mkdir(parents=True, exist_ok=True)
        self._file: TextIO = open(path, "a", encoding="utf-8")  # noqa: SIM115 - long-lived
        self._size = self._file.tell()

    def write(self, line: str) -> None:
        """Append ``line`` (ending in a newline; a cut line keeps it)."""
        if len(line) > self.limit:
            line = truncate(line.rstrip("\n"), self.limit) + "\n"
        size = len(line.encode("utf-8"))  # the file's size is counted in bytes, not characters
        with self._lock:
            if self._size + size > self.max_size and self._size:
                self._rotate()
            self._file.write(line)
            self._file.flush()
            self._size += size

    def _rotate(self) -> None:
        self._file.close()
        _shift(self.path, self.backups)
        if self.backups:
            os.replace(self.path, self.path.with_name(f"{self.path.name}.1"))
        else:
            self.path.unlink()
        self._file = open(self.path, "a", encoding="utf-8")  # noqa: SIM115
        self._size = 0

    def close(self) -> None:
        with self._lock:
            self._file.close()


def rotate_copy_truncate(path: PathLike, max_bytes: int = NODE_LOG_MAX_BYTES,
                         backups: int = NODE_LOG_BACKUPS) -> bool:
    """Rotate a file another process writes (opened for appending) once it is over
    ``max_bytes``: copy it to ``path.1`` (older copies shifted, the oldest dropped), then empty
    it in place, so the writer's next line starts the new file (logrotate's copytruncate).
    True when it rotated; OSError is left to the caller."""
    path = Path(path)
    try:
        if path.stat().st_size <= max_bytes:
            return False
    except FileNotFoundError:
        return False
    if backups:
        _shift(path, backups)
        shutil.copyfile(path, path.with_name(f"{path.name}.1"))
    os.truncate(path, 0)
    return True
