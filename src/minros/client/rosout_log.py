"""The node's side of /rosout: every log record published as a ``rosgraph_msgs/Log``, and the
``~get_loggers``/``~set_logger_level`` services that ``rosconsole`` and rqt_logger_level call.

Built on the client library's own Publisher and Service; ``init_node`` starts it
(:func:`start_node_logging`). The console and the log functions are :mod:`minros.client.log`.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any, Dict

from minros import node
from minros.client import log, params, rostime
from minros.client.services import Service
from minros.client.topics import Publisher

__all__ = ["RosoutHandler", "start_node_logging"]


class _RosoutState:
    def __init__(self) -> None:
        self.publisher: Publisher | None = None
        self.handler: RosoutHandler | None = None
        self.services: list = []
        self.local = threading.local()  # guards against logging from inside publish()


_rosout = _RosoutState()


def _node_topics() -> list:
    """Names of the topics this node publishes or subscribes (the Log message's ``topics``)."""
    me = node.default_node()
    return sorted(set(me.publications) | set(me.subscriptions))


class RosoutHandler(logging.Handler):
    """Publishes every record as a rosgraph_msgs/Log on /rosout."""

    def emit(self, record: logging.LogRecord) -> None:
        publisher = _rosout.publisher
        if publisher is None or getattr(_rosout.local, "busy", False):
            return
        _rosout.local.busy = True
        try:
            from rosgraph_msgs.msg import Log

            try:
                disable_topics = _get_param_cached("/rosout_disable_topics_generation", False)
            except Exception:
                disable_topics = False
            msg = Log(
                level=log.LOGGING_TO_ROS.get(record.levelno, log.INFO),
                name=node.get_caller_id(),
                msg=str(self.format(record)),
                file=record.filename,
                function=getattr(record, "ros_function", record.funcName),
                line=record.lineno,
                topics=[] if disable_topics else _node_topics(),
            )
            try:
                msg.header.stamp = rostime.get_rostime()
            except Exception:  # time not initialised yet: stamp with the wall clock
                msg.header.stamp = rostime._wall_now()
            publisher.publish(msg)
        except Exception:
            # never let a broken /rosout break the caller; say so on the internal logger
            logging.getLogger("rospy.rosout").debug("unable to report to /rosout", exc_info=True)
        finally:
            _rosout.local.busy = False


#: after a failed parameter lookup, /rosout records use the default for this many seconds
#: (a master that hangs must not stall every log call for an XML-RPC timeout)
_PARAM_RETRY = 10.0
_param_failed_at: Dict[str, float] = {}


def _get_param_cached(key: str, default: Any) -> Any:
    failed = _param_failed_at.get(key)
    if failed is not None and time.monotonic() - failed < _PARAM_RETRY:
        return default
    try:
        return params.get_param_cached(key, default)
    except Exception:
        _param_failed_at[key] = time.monotonic()
        return default


def _get_loggers(_request: Any) -> Any:
    from roscpp.msg import Logger
    from roscpp.srv import GetLoggersResponse

    response = GetLoggersResponse()
    for name in list(logging.Logger.manager.loggerDict.keys()):
        level = logging.getLogger(name).getEffectiveLevel()
        response.loggers.append(Logger(name, log._LOGGING_TO_NAME.get(level, "debug")))
    return response


def _set_logger_level(request: Any) -> Any:
    from roscpp.srv import SetLoggerLevelResponse

    level = request.level.upper()
    if level in log._NAME_TO_LOGGING:
        logging.getLogger(request.logger).setLevel(log._NAME_TO_LOGGING[level])
    else:
        logging.getLogger("rospy").error(f"Bad logging level: {level}")
    return SetLoggerLevelResponse()


def start_node_logging(caller_id: str, log_level: int | None, disable_rosout: bool) -> None:
    """Called by ``init_node``: level filter, log file, /rosout publisher, logger services."""
    logger = log._install_console_handler()
    log.start_file_logging(caller_id)
    if log_level is not None:
        logger.setLevel(log.ROS_TO_LOGGING.get(log_level, logging.INFO))
    if not disable_rosout and _rosout.publisher is None:
        from rosgraph_msgs.msg import Log

        _rosout.publisher = Publisher("/rosout", Log, latch=True, queue_size=100)
        _rosout.handler = RosoutHandler()
        logger.addHandler(_rosout.handler)
    if not _rosout.services:
        from roscpp.srv import GetLoggers, SetLoggerLevel

        _rosout.services = [
            Service("~get_loggers", GetLoggers, _get_loggers),
            Service("~set_logger_level", SetLoggerLevel, _set_logger_level),
        ]
