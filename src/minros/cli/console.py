"""``minros console`` / ``rosconsole``: view log messages and a node's logger levels.

``echo [FILTER] [LEVEL]`` prints the /rosout stream (loggers whose name matches the regular
expression FILTER, at LEVEL or above, default warn) as rosconsole does; ``list NODE``,
``get NODE LOGGER`` and ``set NODE LOGGER LEVEL`` go through the node's ``~get_loggers`` and
``~set_logger_level`` services (roscpp/GetLoggers, roscpp/SetLoggerLevel), which every rospy,
roscpp and minros node serves. Texts and exit statuses follow ROS's rosconsole.
"""

from __future__ import annotations

import argparse
import optparse
import os
import re
import sys
from datetime import datetime
from typing import Any, Dict, List

from minros import names
from minros.tools.common import ToolError, run_tool

NAME = "rosconsole"
USAGE = """rosconsole is a command-line tool for configuring the logger level of ROS nodes.

Commands:
\trosconsole get\tdisplay level for a logger
\trosconsole list\tlist loggers for a node
\trosconsole set\tset level for a logger
\trosconsole echo\tprint logger messages

Type rosconsole <command> -h for more detailed usage, e.g. 'rosconsole list -h'
"""
#: rosgraph_msgs/Log levels in increasing severity, and their colours in ``echo``
LEVELS = {"DEBUG": 1, "INFO": 2, "WARN": 4, "ERROR": 8, "FATAL": 16}
COLORS = {"DEBUG": 92, "INFO": 97, "WARN": 93, "ERROR": 91, "FATAL": 95}
SERVICE_TIMEOUT = 5.0


def _init_node() -> None:
    from minros.client.init import init_node

    init_node(NAME, argv=[sys.argv[0]] + [a for a in sys.argv[1:] if ":=" in a], anonymous=True,
              disable_rosout=True)


# ---------------------------------------------------------------------------------------------
# the logger services


def get_loggers(node: str) -> Dict[str, str]:
    """``{logger: level}`` of ``node``, through its ``~get_loggers`` service."""
    from minros.client.services import ServiceProxy, wait_for_service
    from minros.exceptions import ROSException, ServiceException
    from minros.msgs import get_service_class

    service = names.ns_join(node, "get_loggers")
    try:
        wait_for_service(service, timeout=SERVICE_TIMEOUT)
        response = ServiceProxy(service, get_service_class("roscpp/GetLoggers"))()
    except (ROSException, ServiceException) as exc:
        raise ToolError(f"node [{node}] did not answer on [{service}]: {exc}",
                        prefix=f"{NAME}: error: ") from None
    return {logger.name: logger.level.lower() for logger in response.loggers}


def set_logger_level(node: str, logger: str, level: str) -> None:
    from minros.client.services import ServiceProxy
    from minros.exceptions import ServiceException
    from minros.msgs import get_service_class

    service = names.ns_join(node, "set_logger_level")
    try:
        ServiceProxy(service, get_service_class("roscpp/SetLoggerLevel"))(logger=logger, level=level)
    except ServiceException as exc:
        raise ToolError(f"node [{node}] did not set [{logger}] to [{level}]: {exc}",
                        prefix=f"{NAME}: error: ") from None


def _node_logger(node: str, logger: str) -> Dict[str, str]:
    loggers = get_loggers(node)
    if logger not in loggers:
        raise ToolError(f"node {node} does not contain logger {logger}", status=2,
                        prefix=f"{NAME}: error: ")
    return loggers


def _cmd_list(argv: List[str]) -> int:
    p = optparse.OptionParser(usage="usage: %prog list <node>", prog=NAME)
    _options, args = p.parse_args(argv)
    if not args:
        p.error("you must specify a node to list loggers")
    if len(args) > 1:
        p.error("you may only specify one node to list")
    _init_node()
    print("\n".join(get_loggers(names.script_resolve_name(NAME, args[0]))))
    return 0


def _cmd_get(argv: List[str]) -> int:
    p = optparse.OptionParser(usage="usage: %prog get <node> <logger>", prog=NAME)
    _options, args = p.parse_args(argv)
    if len(args) < 2:
        p.error("you must specify a node and a logger")
    _init_node()
    print(_node_logger(names.script_resolve_name(NAME, args[0]), args[1])[args[1]])
    return 0


def _cmd_set(argv: List[str]) -> int:
    usage = ("usage: %prog set <node> <logger> <level>\n\n <level> must be one of ["
             + ", ".join(level.lower() for level in LEVELS) + "]")
    p = optparse.OptionParser(usage=usage, prog=NAME)
    _options, args = p.parse_args(argv)
    if len(args) < 3:
        p.error("you must specify a node, a logger and a level")
    _init_node()
    node = names.script_resolve_name(NAME, args[0])
    _node_logger(node, args[1])
    if args[2].lower() not in (level.lower() for level in LEVELS):
        p.error("invalid level")
    set_logger_level(node, args[1], args[2])
    return 0


class ROSConsoleException(Exception):
    """A node's loggers could not be read or set (rospy.logger_level_service_caller's)."""


class LoggerLevelServiceCaller:
    """The logger services of nodes, as rqt_logger_level and rospy's rosconsole use them:
    which nodes serve ``~set_logger_level``, their loggers and levels, and level changes.
    Node names are resolved in this process's namespace (ROS_NAMESPACE)."""

    def __init__(self) -> None:
        self._current_loggers: List[str] = []
        self._current_levels: Dict[str, str] = {}

    def get_levels(self) -> List[str]:
        """The level names, lower-case as the services answer them, by increasing severity."""
        return [level.lower() for level in LEVELS]

    @staticmethod
    def _resolve(node: str) -> str:
        ns = names.get_ros_namespace()
        return names.resolve_name(names.ns_join(ns, node), ns)

    def get_node_names(self) -> List[str]:
        """The nodes that serve ``<node>/set_logger_level``, sorted."""
        from minros.tools.master import Master

        _pubs, _subs, services = Master("/rosconsole").system_state()
        providers = {name: set(nodes) for name, nodes in services}
        return sorted(node for node in {n for nodes in providers.values() for n in nodes}
                      if node in providers.get(names.ns_join(node, "set_logger_level"), ()))

    def get_loggers(self, node: str) -> List[str]:
        """The loggers of ``node`` (and remembers their levels); ROSConsoleException when the
        node does not answer."""
        try:
            loggers = get_loggers(self._resolve(node))
        except ToolError as exc:
            raise ROSConsoleException(f"node '{node}' doesn't exist or doesn't support query: "
                                      f"{exc}") from None
        self._current_loggers = list(loggers)
        self._current_levels = {name: level.upper() for name, level in loggers.items()}
        return self._current_loggers

    def send_logger_change_message(self, node: str, logger: str, level: str) -> bool:
        """Set ``logger`` of ``node`` to ``level``; False when it already is at that level
        (get_loggers first), ROSConsoleException when the node refuses."""
        if self._current_levels.get(logger, "").upper() == level.upper():
            return False
        try:
            set_logger_level(self._resolve(node), logger, level)
        except ToolError as exc:
            raise ROSConsoleException(f"node '{node}' logger request failed: {exc}") from None
        self._current_levels[logger] = level.upper()
        return True


# ---------------------------------------------------------------------------------------------
# echo


class ConsoleEcho:
    """Prints /rosout messages at or above a level whose logger name matches a pattern."""

    def __init__(self, pattern: str, level: str, nocolor: bool = False, verbose: bool = False,
                 out: Any = None) -> None:
        self.filter = re.compile(pattern)
        self.level = LEVELS[level.upper()]
        self.verbose = verbose
        self.out = out or sys.stdout
        self.labels = {value: (name.ljust(5) if nocolor else f"\033[{COLORS[name]}m{name.ljust(5)}\033[0m")
                       for name, value in LEVELS.items()}
        self.count = 0

    def text(self, msg: Any) -> str | None:
        """The lines for ``msg``, or None when it is filtered out."""
        if msg.level < self.level or not self.filter.search(msg.name):
            return None
        label = self.labels.get(msg.level, str(msg.level))
        text = f"[ {label} ] [\033[1m{msg.name}\033[21m]: {msg.msg}"
        if self.verbose:
            seconds = msg.header.stamp.to_sec()
            stamp = datetime.fromtimestamp(seconds).astimezone()
            text += f"\n          [{stamp} ({seconds:.6f})] [{msg.function}]: {msg.file}:{msg.line}"
        return text

    def __call__(self, msg: Any) -> None:
        text = self.text(msg)
        if text is not None:
            self.count += 1
            print(text, file=self.out, flush=True)


class RosConsoleEcho(ConsoleEcho):
    """rospy.rosconsole's echo: subscribes at once to ``options.topic`` and prints what passes
    ``options.filter`` and ``options.level`` (``options.once``: the first, then shuts the node
    down). Needs an initialised node."""

    LEVEL_COLOR = COLORS
    LEVEL_MAX_LENGTH = max(len(level) for level in LEVELS)

    def __init__(self, options: Any) -> None:
        super().__init__(options.filter, options.level, options.nocolor, options.verbose)
        from minros.client.topics import Subscriber
        from minros.msgs import get_message_class

        self.once = bool(getattr(options, "once", False))
        Subscriber(options.topic, get_message_class("rosgraph_msgs/Log"), self)

    def __call__(self, msg: Any) -> None:
        super().__call__(msg)
        if self.once and self.count:
            from minros import node

            node.signal_shutdown("Done")

    @staticmethod
    def get_levels() -> List[str]:
        """Level names by increasing severity."""
        return sorted(LEVELS, key=LEVELS.__getitem__)


def error(status: int, msg: str) -> None:
    """Print ``rosconsole: error: msg`` on stderr and exit with ``status``."""
    print(f"{NAME}: error: {msg}", file=sys.stderr)
    sys.exit(status)


def _cmd_echo(argv: List[str], prog: str) -> int:
    p = argparse.ArgumentParser(prog=prog, description="Print logger messages")
    p.add_argument("filter", metavar="FILTER", type=str, nargs="?", default=".*",
                   help="regular expression to filter the logger name (default: %(default)s)")
    p.add_argument("level", metavar="LEVEL", type=str, nargs="?", default="warn",
                   choices=[level.lower() for level in LEVELS],
                   help="minimum logger level to print (default: %(default)s)")
    p.add_argument("-1", "--once", action="store_true", dest="once",
                   help="prints one logger message and exits")
    p.add_argument("--topic", action="store", metavar="TOPIC", type=str, default="/rosout",
                   dest="topic", help="topic to read the logger messages from (default: %(default)s)")
    p.add_argument("--nocolor", action="store_true", help="output without color")
    p.add_argument("-v", "--verbose", action="store_true", help="print full logger details")
    args = p.parse_args(argv)
    try:
        echo = ConsoleEcho(args.filter, args.level, args.nocolor, args.verbose)
    except re.error as exc:
        raise ToolError(f"invalid FILTER [{args.filter}]: {exc}", prefix=f"{NAME}: error: ") from None
    _init_node()
    from minros import node
    from minros.client.topics import Subscriber
    from minros.msgs import get_message_class

    def callback(msg: Any) -> None:
        echo(msg)
        if args.once and echo.count:
            node.signal_shutdown("Done")

    Subscriber(args.topic, get_message_class("rosgraph_msgs/Log"), callback)
    node.wait_for_shutdown(None)
    return 0


def main(argv: List[str], prog: str = NAME) -> int:
    argv = names.strip_remapping_args(list(argv))
    if not argv or argv[0] not in ("get", "list", "set", "echo"):
        print(USAGE)
        return getattr(os, "EX_USAGE", 1)
    command, rest = argv[0], argv[1:]
    if command == "echo":
        return run_tool(lambda: _cmd_echo(rest, f"{NAME} echo"))
    handler = {"get": _cmd_get, "list": _cmd_list, "set": _cmd_set}[command]
    return run_tool(lambda: handler(rest), io_message="Network communication failed; most likely "
                    "failed to communicate with master")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
