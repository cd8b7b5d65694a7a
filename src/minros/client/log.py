"""Node logging as rospy does it: the ``rosout`` Python logger, the console, and /rosout.

``loginfo`` and friends log to the Python logger ``rosout`` (or ``rosout.<logger_name>``), so
plain ``logging.getLogger('rosout')`` users get the same treatment. Two handlers hang off that
logger:

* the console handler (installed on import, so logging before ``init_node`` prints too) writes
  one line per record in the ``ROSCONSOLE_FORMAT`` (default ``[${severity}] [${time}]:
  ${message}``); DEBUG and INFO go to stdout, WARN and worse to stderr;
* the /rosout handler (:mod:`minros.client.rosout_log`, installed by ``init_node`` unless
  ``disable_rosout``) publishes a ``rosgraph_msgs/Log`` per record.

The console line itself is built by the pure function :func:`format_console_line` and printed
by rosgraph.roslogging's handler (:mod:`minros.roslogging`).
"""

from __future__ import annotations

import hashlib
import inspect
import logging
import os
import sys
import threading
import time
from typing import Any, Dict, Mapping, Tuple

from minros import logfiles, node
from minros.client import rostime
from minros.rosenv import ros_log_dir
from minros.roslogging import (  # noqa: F401 - the console line is rosgraph.roslogging's
    DEFAULT_FORMAT,
    RosStreamHandler,
    format_console_line,
    set_console_sources,
)

__all__ = [
    "DEBUG", "INFO", "WARN", "ERROR", "FATAL",
    "logdebug", "loginfo", "logwarn", "logerr", "logerror", "logfatal", "logout",
    "logdebug_throttle", "loginfo_throttle", "logwarn_throttle", "logerr_throttle",
    "logfatal_throttle",
    "logdebug_throttle_identical", "loginfo_throttle_identical", "logwarn_throttle_identical",
    "logerr_throttle_identical", "logfatal_throttle_identical",
    "logdebug_once", "loginfo_once", "logwarn_once", "logerr_once", "logfatal_once",
    "format_console_line",
]

# rosgraph_msgs/Log levels (also rospy's level constants)
DEBUG = 1
INFO = 2
WARN = 4
ERROR = 8
FATAL = 16

#: rospy level -> Python logging level
ROS_TO_LOGGING: Dict[int, int] = {
    DEBUG: logging.DEBUG, INFO: logging.INFO, WARN: logging.WARNING,
    ERROR: logging.ERROR, FATAL: logging.CRITICAL,
}
#: Python logging level -> rospy level
LOGGING_TO_ROS: Dict[int, int] = {v: k for k, v in ROS_TO_LOGGING.items()}
#: level names accepted by ~set_logger_level (upper-cased first)
_NAME_TO_LOGGING = {"DEBUG": logging.DEBUG, "INFO": logging.INFO, "WARN": logging.WARNING,
                    "ERROR": logging.ERROR, "FATAL": logging.CRITICAL}
_LOGGING_TO_NAME = {logging.DEBUG: "debug", logging.INFO: "info", logging.WARNING: "warn",
                    logging.ERROR: "error", logging.CRITICAL: "fatal", logging.NOTSET: "debug"}

ROSOUT_LOGGER = "rosout"


# --------------------------------------------------------------------------- console

def _ros_time_or_none() -> float | None:
    """The simulated time for the console's ``${time}``, or None on wall-clock time."""
    if rostime.is_wallclock() or not rostime.is_rostime_initialized():
        return None
    return rostime.get_time()


#: the console handler is rosgraph.roslogging's, fed this node's clock and name
ConsoleHandler = RosStreamHandler
set_console_sources(_ros_time_or_none, node.get_caller_id)


def _install_console_handler() -> logging.Logger:
    logger = logging.getLogger(ROSOUT_LOGGER)
    if not any(isinstance(h, ConsoleHandler) for h in logger.handlers):
        logger.addHandler(ConsoleHandler())
    if logger.level == logging.NOTSET:  # rospy's logging config gives 'rosout' level INFO
        logger.setLevel(logging.INFO)
    return logger


_install_console_handler()
# rospy's internal loggers ('rospy.*') stay silent unless the user configures logging
logging.getLogger("rospy").addHandler(logging.NullHandler())


# --------------------------------------------------------------------------- the node's log file

#: rospy's log file line format (python_logging.conf's defaultFormatter)
FILE_FORMAT = "[%(name)s][%(levelname)s] %(asctime)s: %(message)s"


def node_log_filename(caller_id: str, mappings: Dict[str, str] | None = None,
                      env: Mapping[str, str] | None = None) -> str:
    """Where rospy writes a node's log: ``__log:=FILE``, else ``$ROS_LOG_DIR/<node>.log``.

    The node name has its slashes turned into underscores, without the leading one
    (``/ns/talker`` -> ``ns_talker.log``); the log directory defaults to ``$ROS_HOME/log``
    and then ``~/.ros/log``.
    """
    env = os.environ if env is None else env
    if mappings and "__log" in mappings:
        return os.path.abspath(mappings["__log"])
    log_dir = str(ros_log_dir(env))
    name = caller_id.replace("/", "_")
    if name.startswith("_"):
        name = name[1:]
    return os.path.join(log_dir, name + ".log")


def start_file_logging(caller_id: str) -> None:
    """rospy's logging config: every logger at INFO and above also goes to the node's file
    (rotated at 50 MB keeping 4, lines truncated: they may quote what a peer sent)."""
    filename = node_log_filename(caller_id, node.get_mappings())
    root = logging.getLogger()
    if any(getattr(h, "_minros_node_log", False) for h in root.handlers):
        return
    try:
        os.makedirs(os.path.dirname(filename), exist_ok=True)
        handler = logfiles.rotating_handler(filename, FILE_FORMAT)  # rospy's 50 MB x 4
    except OSError as exc:
        # a node without a writable log directory still runs, as in rospy
        sys.stderr.write(f"WARNING: cannot create log file [{filename}]: {exc}\n")
        return
    handler.setLevel(logging.DEBUG)
    handler._minros_node_log = True  # type: ignore[attr-defined]
    root.addHandler(handler)
    if root.level == logging.WARNING:  # Python's default: rospy's config says INFO
        root.setLevel(logging.INFO)


# --------------------------------------------------------------------------- log functions

_Key = Tuple[str, int, int]


def _frame_key(frame: Any) -> _Key:
    """Identifies one call site: file, line and bytecode offset of the caller."""
    return (frame.f_code.co_filename, frame.f_lineno, frame.f_lasti)


def _now_for_throttle() -> float:
    if rostime.is_rostime_initialized():
        return rostime.get_time()
    return time.time()  # before init_node: wall clock rather than an error


class _Throttle:
    """Lets a call site through at most once per ``period`` seconds of ROS time."""

    def __init__(self) -> None:
        self.last: Dict[_Key, float] = {}
        self.lock = threading.Lock()

    def __call__(self, key: _Key, period: float, now: float | None = None) -> bool:
        now = _now_for_throttle() if now is None else now
        with self.lock:
            last = self.last.get(key)
            if last is None or now - last > period:
                self.last[key] = now
                return True
            if last > now:  # time jumped backwards: forget everything
                self.last = {key: now}
                return True
            return False


class _Identical:
    """Lets a call site through only when its message differs from the previous one."""

    def __init__(self) -> None:
        self.last: Dict[_Key, str] = {}
        self.lock = threading.Lock()

    def __call__(self, key: _Key, msg: Any) -> bool:
        digest = hashlib.md5(str(msg).encode()).hexdigest()
        with self.lock:
            if self.last.get(key) != digest:
                self.last[key] = digest
                return True
            return False


class _Once:
    def __init__(self) -> None:
        self.seen: set = set()
        self.lock = threading.Lock()

    def __call__(self, key: _Key) -> bool:
        with self.lock:
            if key in self.seen:
                return False
            self.seen.add(key)
            return True


_throttle = _Throttle()
_identical = _Identical()
_once = _Once()


def _user_frame():
    """The frame that called the public log function (two levels above ``_base_logger``)."""
    frame = inspect.currentframe()
    # _user_frame <- _base_logger <- log* <- user
    return frame.f_back.f_back.f_back  # type: ignore[union-attr]


def _function_name(frame: Any) -> str:
    """``Class.method`` when the caller is a method (as rospy reports it), else the function."""
    name = frame.f_code.co_name
    owner = frame.f_locals.get("self")
    if owner is not None:
        name = f"{owner.__class__.__name__}.{name}"
    return name


def _base_logger(msg: Any, args: tuple, kwargs: dict, level: int, throttle: float | None = None,
                 throttle_identical: bool = False, once: bool = False) -> None:
    logger = logging.getLogger(ROSOUT_LOGGER)
    name = kwargs.pop("logger_name", None)
    if name:
        logger = logger.getChild(name)
    frame = _user_frame()
    if once:
        if not _once(_frame_key(frame)):
            return
    elif throttle_identical:
        key = _frame_key(frame)
        elapsed = throttle is not None and _throttle(key, throttle)
        # both checks run so each keeps its own state up to date
        if not _identical(key, msg) and not elapsed:
            return
    elif throttle:
        if not _throttle(_frame_key(frame), throttle):
            return
    if not logger.isEnabledFor(level):
        return
    extra = kwargs.pop("extra", None) or {}
    extra.setdefault("ros_function", _function_name(frame))
    # stacklevel 3 skips _base_logger and log*, so file/line name the user's call site
    logger.log(level, msg, *args, extra=extra, stacklevel=3, **kwargs)


def logdebug(msg: Any, *args: Any, **kwargs: Any) -> None:
    """Log at DEBUG (shown only with ``log_level=rospy.DEBUG``)."""
    _base_logger(msg, args, kwargs, logging.DEBUG)


def loginfo(msg: Any, *args: Any, **kwargs: Any) -> None:
    """Log at INFO: stdout and /rosout."""
    _base_logger(msg, args, kwargs, logging.INFO)


def logwarn(msg: Any, *args: Any, **kwargs: Any) -> None:
    """Log at WARN: stderr and /rosout."""
    _base_logger(msg, args, kwargs, logging.WARNING)


def logerr(msg: Any, *args: Any, **kwargs: Any) -> None:
    """Log at ERROR: stderr and /rosout."""
    _base_logger(msg, args, kwargs, logging.ERROR)


def logfatal(msg: Any, *args: Any, **kwargs: Any) -> None:
    """Log at FATAL: stderr and /rosout."""
    _base_logger(msg, args, kwargs, logging.CRITICAL)


logout = loginfo  # rospy's deprecated name
logerror = logerr


def logdebug_throttle(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.DEBUG, throttle=period)


def loginfo_throttle(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    """Log at INFO at most once per ``period`` seconds from this call site."""
    _base_logger(msg, args, kwargs, logging.INFO, throttle=period)


def logwarn_throttle(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.WARNING, throttle=period)


def logerr_throttle(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.ERROR, throttle=period)


def logfatal_throttle(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.CRITICAL, throttle=period)


def logdebug_throttle_identical(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.DEBUG, throttle=period, throttle_identical=True)


def loginfo_throttle_identical(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    """Log at INFO when the message changed, or at least ``period`` seconds went by."""
    _base_logger(msg, args, kwargs, logging.INFO, throttle=period, throttle_identical=True)


def logwarn_throttle_identical(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.WARNING, throttle=period, throttle_identical=True)


def logerr_throttle_identical(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.ERROR, throttle=period, throttle_identical=True)


def logfatal_throttle_identical(period: float, msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.CRITICAL, throttle=period, throttle_identical=True)


def logdebug_once(msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.DEBUG, once=True)


def loginfo_once(msg: Any, *args: Any, **kwargs: Any) -> None:
    """Log at INFO the first time this call site runs, never again."""
    _base_logger(msg, args, kwargs, logging.INFO, once=True)


def logwarn_once(msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.WARNING, once=True)


def logerr_once(msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.ERROR, once=True)


def logfatal_once(msg: Any, *args: Any, **kwargs: Any) -> None:
    _base_logger(msg, args, kwargs, logging.CRITICAL, once=True)
