"""Python logging the ROS way (rosgraph.roslogging): the console line, the logger class that
names a method's caller ``Class.method``, and ``configure_logging``, which sets logging up from
ROS's configuration file and points it at a file in ROS's log directory.

The console line (:func:`format_console_line`) is a pure function of ROSCONSOLE_FORMAT and one
record; :class:`RosStreamHandler` prints it, DEBUG and INFO to stdout, WARN and worse to
stderr. Its ``${time}`` (simulated time) and ``${node}`` come from the client library, which
registers them with :func:`set_console_sources` (this module sits below it).

``configure_logging`` reads, first found: ROS_PYTHON_LOG_CONFIG_FILE, ``python_logging.conf``
or ``.yaml`` in ``$ROS_HOME/config``, in ``$ROS_ETC_DIR`` (``/etc/ros``), then the copy of
ROS's ``python_logging.conf`` in the bundled ``rosgraph`` package's ``conf/``.
"""

from __future__ import annotations

import logging
import logging.config
import os
import sys
import time
from pathlib import Path
from types import FrameType
from typing import Any, Callable, Dict, Mapping, Optional, Tuple

from minros import packages, rosenv

#: Python level name -> the severity word ROS prints, and its terminal colour
SEVERITY: Dict[str, Tuple[str, Optional[str]]] = {
    "DEBUG": ("DEBUG", "\033[32m"),
    "INFO": ("INFO", None),
    "WARNING": ("WARN", "\033[33m"),
    "ERROR": ("ERROR", "\033[31m"),
    "CRITICAL": ("FATAL", "\033[31m"),
}
COLOR_RESET = "\033[0m"
DEFAULT_FORMAT = "[${severity}] [${time}]: ${message}"
CONFIG_NAME = "python_logging"


class LoggingException(Exception):
    """Logging cannot be set up as asked (a file where the log directory should be)."""


# ---------------------------------------------------------------------------------------------
# the console line

def _expand_strftime_tag(text: str, tag: str, suffix: str) -> str:
    """Replace every ``${tag:FORMAT}`` by ``time.strftime(FORMAT)`` (+ ``suffix``)."""
    opener = "${" + tag + ":"
    while opener in text:
        start = text.index(opener)
        end = text.find("}", start + len(opener))
        if end < 0:  # unterminated tag: leave the rest alone rather than loop forever
            break
        fmt = text[start + len(opener):end]
        text = text[:start] + time.strftime(fmt) + suffix + text[end + 1:]
    return text


def format_console_line(fmt: str, *, severity: str, message: str, wall_time: float,
                        ros_time: float | None = None, node: str = "", logger: str = "",
                        file: str = "", line: int = 0, function: str = "",
                        thread: Any = "") -> str:
    """One console line (without newline) for a log record, as rospy's console prints it.

    ``fmt`` uses ROSCONSOLE_FORMAT tags: ``${severity} ${message} ${time} ${time:STRFTIME}
    ${walltime} ${walltime:STRFTIME} ${node} ${logger} ${file} ${line} ${function} ${thread}``.
    ``${time}`` is the wall time as ``%f``, followed by ``, <ros time>`` when the node runs on
    simulated time (``ros_time`` given).
    """
    sim_suffix = "" if ros_time is None else f", {ros_time:f}"
    out = fmt.replace("${severity}", severity)
    out = out.replace("${message}", str(message))
    out = out.replace("${walltime}", f"{wall_time:f}")
    out = _expand_strftime_tag(out, "walltime", "")
    out = out.replace("${thread}", str(thread))
    out = out.replace("${logger}", str(logger))
    out = out.replace("${file}", str(file))
    out = out.replace("${line}", str(line))
    out = out.replace("${function}", str(function))
    out = out.replace("${node}", node)
    out = out.replace("${time}", f"{wall_time:f}" + sim_suffix)
    out = _expand_strftime_tag(out, "time", sim_suffix)
    return out


class _Sources:
    """Where the console gets simulated time and the node's name (the client library's)."""

    ros_time: Callable[[], Optional[float]] = staticmethod(lambda: None)
    node_name: Callable[[], str] = staticmethod(lambda: "<unknown_node_name>")


def set_console_sources(ros_time: Callable[[], Optional[float]],
                        node_name: Callable[[], str]) -> None:
    """Called once by the client library: ``ros_time()`` is the simulated time or None on the
    wall clock, ``node_name()`` the node's name."""
    _Sources.ros_time = staticmethod(ros_time)
    _Sources.node_name = staticmethod(node_name)


class RosStreamHandler(logging.Handler):
    """Writes records in ROSCONSOLE_FORMAT: DEBUG/INFO to stdout, WARN and worse to stderr,
    coloured on a terminal when ``colorize``.

    Without explicit streams, ``sys.stdout``/``sys.stderr`` are looked up per record, so a
    test runner that redirects them later is honoured."""

    _plain = logging.Formatter()

    def __init__(self, colorize: bool = True, stdout: Any = None, stderr: Any = None) -> None:
        super().__init__()
        self._colorize = colorize
        self._stdout = stdout
        self._stderr = stderr

    def emit(self, record: logging.LogRecord) -> None:
        try:
            severity, color = SEVERITY.get(record.levelname, (record.levelname, None))
            line = format_console_line(
                os.environ.get("ROSCONSOLE_FORMAT", DEFAULT_FORMAT),
                severity=severity,
                message=self._plain.format(record),
                wall_time=time.time(),
                ros_time=_Sources.ros_time(),
                node=_Sources.node_name(),
                logger=record.name,
                file=record.pathname,
                line=record.lineno,
                function=getattr(record, "ros_function", record.funcName),
                thread=record.thread,
            ) + "\n"
            if record.levelno < logging.WARNING:
                stream = self._stdout or sys.stdout
            else:
                stream = self._stderr or sys.stderr
            if self._colorize and color and hasattr(stream, "isatty") and stream.isatty():
                line = color + line + COLOR_RESET
            stream.write(line)
            stream.flush()
        except Exception:
            self.handleError(record)


# ---------------------------------------------------------------------------------------------
# the caller of a record

_LOGGING_FILE = os.path.normcase(logging.__file__)


class RospyLogger(logging.getLoggerClass()):  # type: ignore[misc]
    """A logger whose records name a method's caller ``Class.method``, as rospy's do."""

    def findCaller(self, stack_info: bool = False, stacklevel: int = 1) -> Tuple[Any, ...]:
        frame: Optional[FrameType] = sys._getframe(1)
        while frame is not None and os.path.normcase(frame.f_code.co_filename) == _LOGGING_FILE:
            frame = frame.f_back
        for _ in range(stacklevel - 1):
            if frame is None or frame.f_back is None:
                break
            frame = frame.f_back
        if frame is None:
            return "(unknown file)", 0, "(unknown function)", None
        code = frame.f_code
        name = code.co_name
        owner = frame.f_locals.get("self")
        if owner is not None:
            name = f"{owner.__class__.__name__}.{name}"
        sinfo = None
        if stack_info:
            import traceback

            sinfo = "Stack (most recent call last):\n" + "".join(traceback.format_stack(frame))
        return code.co_filename, frame.f_lineno, name, sinfo


logging.setLoggerClass(RospyLogger)


def _adopt_rospy_loggers() -> None:
    """Loggers of rospy's names made before this module was imported (minros's node names its
    'rosout' logger on import) become RospyLoggers too; the class adds behaviour, not state."""
    for name, logger in list(logging.Logger.manager.loggerDict.items()):
        if type(logger) is logging.Logger and (name == "rosout" or name.startswith("rospy")):
            logger.__class__ = RospyLogger


_adopt_rospy_loggers()


# ---------------------------------------------------------------------------------------------
# log files and configuration

def renew_latest_logdir(logfile_dir: str) -> bool:
    """Point ``<log dir>/latest`` at ``logfile_dir``; False when ``latest`` is a real folder."""
    latest = os.path.join(os.path.dirname(logfile_dir), "latest")
    if os.path.lexists(latest):
        if not os.path.islink(latest):
            return False
        os.remove(latest)
    os.symlink(logfile_dir, latest)
    return True


def makedirs_with_parent_perms(p: str) -> None:
    """Create folder ``p`` (and missing parents) with the owner and mode of the nearest
    existing parent: a root process logging into a user's ROS_HOME leaves it the user's."""
    p = os.path.abspath(p)
    parent = os.path.dirname(p)
    if os.path.exists(p) or not p or parent == p:
        return
    makedirs_with_parent_perms(parent)
    parent_stat = os.stat(parent)
    os.mkdir(p)
    stat = os.stat(p)
    if (parent_stat.st_uid, parent_stat.st_gid) != (stat.st_uid, stat.st_gid):
        os.chown(p, parent_stat.st_uid, parent_stat.st_gid)
    if parent_stat.st_mode != stat.st_mode:
        os.chmod(p, parent_stat.st_mode)


def find_config_file(env: Optional[Mapping[str, str]] = None) -> Optional[str]:
    """The logging configuration ROS would load (see the module's description), or None."""
    env = os.environ if env is None else env
    explicit = env.get("ROS_PYTHON_LOG_CONFIG_FILE")
    if explicit:
        return explicit
    folders = [rosenv.ros_home(env) / "config", Path(env.get("ROS_ETC_DIR") or "/etc/ros")]
    rosgraph_dir = packages.find_package("rosgraph")
    if rosgraph_dir is not None:
        folders.append(rosgraph_dir / "conf")
    for folder in folders:
        for extension in ("conf", "yaml"):
            candidate = folder / f"{CONFIG_NAME}.{extension}"
            if candidate.is_file():
                return str(candidate)
    return None


def configure_logging(logname: str, level: int = logging.INFO, filename: str | None = None,
                      env: Optional[Mapping[str, str]] = None) -> Optional[str]:
    """Set Python logging up from ROS's configuration, logging to ``filename`` in the ROS log
    directory (default ``<logname>-<pid>.log``); returns that path, or None when the folder
    cannot be made (a warning on stderr: command-line tools must keep working)."""
    env = os.environ if env is None else env
    logname = logname or "unknown"
    log_dir = str(rosenv.ros_log_dir(env))
    log_filename = os.path.join(log_dir, filename or f"{logname}-{os.getpid()}.log")
    logfile_dir = os.path.dirname(log_filename)
    if not os.path.exists(logfile_dir):
        try:
            makedirs_with_parent_perms(logfile_dir)
        except OSError:
            if os.path.exists(logfile_dir):
                sys.stderr.write(f"WARNING: Could not change permissions for folder "
                                 f"[{logfile_dir}], make sure that the parent folder has correct "
                                 "permissions.\n")
            else:
                sys.stderr.write(f"WARNING: cannot create log directory [{logfile_dir}]. Please "
                                 "set ROS_LOG_DIR to a writable location.\n")
            return None
    elif os.path.isfile(logfile_dir):
        raise LoggingException(f"Cannot save log files: file [{logfile_dir}] is in the way")
    if logfile_dir != log_dir and sys.platform != "win32":
        try:
            if not renew_latest_logdir(logfile_dir):
                sys.stderr.write("INFO: cannot create a symlink to latest log directory\n")
        except OSError as exc:
            sys.stderr.write(f"INFO: cannot create a symlink to latest log directory: {exc}\n")
    config_file = find_config_file(env)
    if config_file is None or not os.path.isfile(config_file):
        sys.stderr.write("WARNING: cannot load logging configuration file, logging is disabled\n")
        logging.getLogger(logname).setLevel(logging.CRITICAL)
        return log_filename
    os.environ["ROS_LOG_FILENAME"] = log_filename  # the configuration's file handler reads it
    if config_file.endswith((".yaml", ".yml")):
        import yaml

        with open(config_file) as f:
            config = yaml.safe_load(f)
        config.setdefault("version", 1)
        logging.config.dictConfig(config)
    else:
        logging.config.fileConfig(config_file, disable_existing_loggers=False)
    return log_filename
