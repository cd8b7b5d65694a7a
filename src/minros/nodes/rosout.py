"""The rosout node: aggregates ``/rosout`` onto ``/rosout_agg`` and into ``rosout.log``.

Built on the public minros (rospy) API like any other node. ``minros core`` starts it as a
separate process (as roscore starts ``rosout/rosout``) with ``python -m minros.nodes.rosout``.

The log file is ``$ROS_LOG_DIR/<run_id>/rosout.log`` (``$ROS_HOME/log`` or ``~/.ros/log`` when
``ROS_LOG_DIR`` is unset), one line per message in the C++ rosout format::

    <secs>.<nsecs> <LEVEL> <node> [<file>:<line>(<function>)] [topics: /a, /b] <text>

and it is rotated at ``MAX_FILE_SIZE`` bytes keeping ``MAX_BACKUPS`` old files.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from pathlib import Path
from typing import Any, List, TextIO

from minros.rosenv import ros_log_dir

MAX_FILE_SIZE = 100 * 1024 * 1024
MAX_BACKUPS = 10
_LEVELS = {1: "DEBUG", 2: "INFO", 4: "WARN", 8: "ERROR", 16: "FATAL"}


def format_line(msg: Any) -> str:
    """One rosout.log line for a rosgraph_msgs/Log message."""
    stamp = msg.header.stamp
    level = _LEVELS.get(msg.level, str(msg.level))
    topics = ", ".join(msg.topics)
    return (f"{stamp.secs}.{stamp.nsecs:09d} {level} {msg.name} "
            f"[{msg.file}:{msg.line}({msg.function})] [topics: {topics}] {msg.msg}\n")


class RotatingLog:
    """Append-only text log rotated by size (``rosout.log`` -> ``rosout.log.1`` ...)."""

    def __init__(self, path: Path, max_size: int = MAX_FILE_SIZE, backups: int = MAX_BACKUPS) -> None:
        self.path = path
        self.max_size = max_size
        self.backups = backups
        self._lock = threading.Lock()
        path.parent.mkdir(parents=True, exist_ok=True)
        self._file: TextIO = open(path, "a", encoding="utf-8")  # noqa: SIM115 - long-lived
        self._size = self._file.tell()

    def write(self, line: str) -> None:
        size = len(line.encode("utf-8"))  # the file's size is counted in bytes, not characters
        with self._lock:
            if self._size + size > self.max_size and self._size:
                self._rotate()
            self._file.write(line)
            self._file.flush()
            self._size += size

    def _rotate(self) -> None:
        self._file.close()
        for i in range(self.backups - 1, 0, -1):
            older = self.path.with_name(f"{self.path.name}.{i}")
            if older.exists():
                os.replace(older, self.path.with_name(f"{self.path.name}.{i + 1}"))
        if self.backups:
            os.replace(self.path, self.path.with_name(f"{self.path.name}.1"))
        else:
            self.path.unlink()
        self._file = open(self.path, "a", encoding="utf-8")  # noqa: SIM115
        self._size = 0

    def close(self) -> None:
        with self._lock:
            self._file.close()


def _exit_with_core(minros: Any) -> None:
    """When started by ``minros core`` (which sets MINROS_CORE_PID), shut down if it dies:
    a core killed with SIGKILL must not leave an orphaned rosout behind."""
    try:
        core_pid = int(os.environ.get("MINROS_CORE_PID", ""))
    except ValueError:
        return

    def watch() -> None:
        while os.getppid() == core_pid:
            time.sleep(0.5)
        try:
            minros.signal_shutdown("minros core went away")
        except Exception:  # noqa: BLE001 - e.g. not initialized yet: we exit below anyway
            pass
        time.sleep(3.0)  # a clean shutdown has this long (the master is gone: nothing to wait for)
        os._exit(0)

    threading.Thread(target=watch, name="rosout-core-watch", daemon=True).start()


def main(argv: List[str] | None = None) -> int:
    argv = sys.argv if argv is None else argv
    import minros
    from rosgraph_msgs.msg import Log

    _exit_with_core(minros)  # before init_node, which waits for a master that may be gone
    minros.init_node("rosout", argv=argv, disable_rosout=True, disable_rostime=True)
    run_id = minros.get_param("/run_id", "")
    directory = ros_log_dir() / run_id if run_id else ros_log_dir()
    try:
        log: RotatingLog | None = RotatingLog(directory / "rosout.log")
    except OSError as exc:
        print(f"rosout: cannot write {directory / 'rosout.log'}: {exc.strerror or exc}",
              file=sys.stderr)
        log = None
    agg = minros.Publisher("/rosout_agg", Log, queue_size=100)

    def on_log(msg: Any) -> None:
        agg.publish(msg)
        if log is not None:
            try:
                log.write(format_line(msg))
            except OSError:
                pass  # a full disk must not stop the aggregation

    minros.Subscriber("/rosout", Log, on_log, queue_size=1000)
    minros.spin()
    if log is not None:
        log.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
