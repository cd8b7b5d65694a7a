"""The rosout node: aggregates ``/rosout`` onto ``/rosout_agg`` and into ``rosout.log``.

Built on the public minros (rospy) API like any other node. ``minros core`` starts it as a
separate process (as roscore starts ``rosout/rosout``) with ``python -m minros.nodes.rosout``.

The log file is ``$ROS_LOG_DIR/<run_id>/rosout.log`` (``$ROS_HOME/log`` or ``~/.ros/log`` when
``ROS_LOG_DIR`` is unset), one line per message in the C++ rosout format::

    <secs>.<nsecs> <LEVEL> <node> [<file>:<line>(<function>)] [topics: /a, /b] <text>

and it is rotated as the C++ rosout rotates it (100 MiB, 10 old files), each line truncated
(:mod:`minros.logfiles`): its text is whatever a node sent.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from typing import Any, List

from minros.logfiles import RotatingLog
from minros.rosenv import ros_log_dir

_LEVELS = {1: "DEBUG", 2: "INFO", 4: "WARN", 8: "ERROR", 16: "FATAL"}


def format_line(msg: Any) -> str:
    """One rosout.log line for a rosgraph_msgs/Log message."""
    stamp = msg.header.stamp
    level = _LEVELS.get(msg.level, str(msg.level))
    topics = ", ".join(msg.topics)
    return (f"{stamp.secs}.{stamp.nsecs:09d} {level} {msg.name} "
            f"[{msg.file}:{msg.line}({msg.function})] [topics: {topics}] {msg.msg}\n")


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
