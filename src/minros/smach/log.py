"""smach's loggers and shutdown check, replaceable at run time.

Plain smach prints (``[  INFO ] : text``); ``smach_ros`` routes the four levels to rospy's
loggers and the shutdown check to ``rospy.is_shutdown`` when imported. The functions here
look the current ones up on every call, so code holding ``smach.loginfo`` follows a later
``set_loggers``.
"""

from __future__ import annotations

from typing import Callable, Dict

Logger = Callable[[str], object]


def _printer(tag: str) -> Logger:
    def emit(msg: str) -> None:
        print(f"[{tag}] : {msg}")
    return emit


_loggers: Dict[str, Logger] = {
    "info": _printer("  INFO "), "warn": _printer("  WARN "),
    "debug": _printer(" DEBUG "), "error": _printer(" ERROR "),
}
_shutdown_check: Callable[[], bool] = lambda: False  # noqa: E731 - replaced by smach_ros


def loginfo(msg: object) -> None:
    _loggers["info"](str(msg))


def logwarn(msg: object) -> None:
    _loggers["warn"](str(msg))


def logdebug(msg: object) -> None:
    _loggers["debug"](str(msg))


def logerr(msg: object) -> None:
    _loggers["error"](str(msg))


def set_loggers(info: Logger, warn: Logger, debug: Logger, error: Logger) -> None:
    """Route smach's log output (ROS's argument order: info, warn, debug, error)."""
    _loggers.update(info=info, warn=warn, debug=debug, error=error)


def is_shutdown() -> bool:
    """Whether running state machines should stop (always False until a check is set)."""
    return bool(_shutdown_check())


def set_shutdown_check(cb: Callable[[], bool]) -> None:
    global _shutdown_check
    _shutdown_check = cb


__all__ = ["set_loggers", "loginfo", "logwarn", "logerr", "logdebug", "is_shutdown",
           "set_shutdown_check"]
