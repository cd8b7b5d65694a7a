"""``rostopic echo`` (from a live topic or a bag) and ``rostopic list -b``: decode with the
publisher's definition, filter, select a field, print as YAML or CSV (``-p``)."""

from __future__ import annotations

import os
import sys
import threading
import time
from typing import Any, Callable, Dict, List

from minros import names
from minros.cli.topic_common import (
    NAME,
    checked_master,
    compile_filter,
    init_tool_node,
    ros_now,
    spin_until,
    wait_topic_type,
)
from minros.tools.common import ToolError, option_parser, resolve


def _open_bag(path: str) -> Any:
    """The bag at ``path`` for reading; problems are reported as rostopic reports them."""
    if not os.path.exists(path):
        raise ToolError(f"bag file [{path}] does not exist")
    from minros.bag import Bag, ROSBagException, ROSBagUnindexedException

    try:
        return Bag(path)
    except ROSBagUnindexedException:
        raise ToolError(f"bag unindexed: {path}.  Run rosbag reindex.") from None
    except ROSBagException as exc:
        raise ToolError(f"reading {path}: {exc}") from None


def list_bag(path: str, topic: str | None) -> int:
    """rostopic list -b: the topics in order of their first message, or one topic's count."""
    with _open_bag(path) as bag:
        if topic:
            ns = names.make_global_ns(topic)
            stamps = [t for top, _m, t in bag.read_messages(raw=True) if top == topic or top.startswith(ns)]
            if not stamps:
                raise ToolError(f"no messages of [{topic}] in {path}")
            first, last = (time.strftime("%d %b %Y %H:%M:%S", time.localtime(t.to_sec()))
                           for t in (stamps[0], stamps[-1]))
            print(f"{len(stamps)} message(s) from {first} to {last}")
            return 0
        seen: Dict[str, None] = {}
        for top, _m, _t in bag.read_messages(raw=True):
            if top not in seen:
                seen[top] = None
                print(top)
    return 0


class _BagMsg:
    """A message read from a bag, in the shape the echo callback takes (AnyMsg's)."""

    __slots__ = ("_buff", "_connection_header")

    def __init__(self, buff: bytes, header: Dict[str, str]) -> None:
        self._buff = buff
        self._connection_header = header


def _echo_bag(path: str, topic: str | None, args: Any, filter_fn: Callable | None) -> int:
    """rostopic echo -b: the messages of ``topic`` (or, with -a, of every topic) in a bag."""
    echo: _Echo | None = None
    with _open_bag(path) as bag:
        # a ROS 2 recording's topic that does not convert to ROS 1: say why, not nothing
        for skipped, (ros2_type, reason) in getattr(bag._reader, "skipped", {}).items():
            if topic is not None and (topic == skipped or topic.startswith(skipped + "/")):
                raise ToolError(f"{skipped} [{ros2_type}] in {path} does not read as ROS 1: "
                                f"{reason}")
        for top, raw, stamp, header in bag.read_messages(raw=True, return_connection_header=True):
            if top[0] != "/":
                top = resolve(NAME, top)
            field = ""
            if topic is not None and top != topic:
                if not topic.startswith(top + "/"):
                    continue
                field = topic[len(top) + 1:]
            if echo is None:
                echo = _Echo(topic or top, field, args, filter_fn, top)
            echo.real_topic = top
            echo.stamp = stamp
            echo(_BagMsg(raw[1], {k: v.decode() for k, v in header.items()}))
            if echo.done:
                break
    if echo is not None and echo.error:
        raise ToolError(echo.error)
    return 0


class _Echo:
    """The echo callback: decode, filter, select a field, print; counts for ``-n``."""

    def __init__(self, topic: str, field_path: str, options: Any, filter_fn: Callable | None,
                 real_topic: str = '') -> None:
        from minros.tools.decode import Decoder
        from minros.tools.echo import (
            make_field_filter,
            make_field_getter,
            make_value_transform,
        )

        self.topic = topic
        self.real_topic = real_topic or topic
        self.field_path = field_path
        self.getter = make_field_getter(field_path) if field_path else None
        self.decoder = Decoder()
        self.plot = options.plot
        self.offset = options.offset_time
        self.width = options.fixed_numeric_width
        self.prefix = "\033[2J\033[;H" if options.clear and not options.plot else ""
        self.suffix = "" if options.plot else "\n---"
        self.field_filter = make_field_filter(options.nostr, options.noarr) if options.plot else None
        self.transform = None if options.plot else make_value_transform(options.nostr, options.noarr)
        self.filter_fn = filter_fn
        self.max_count = options.msg_count
        self.count = 0
        self.done = False
        self.first = True
        self.error: str | None = None
        self.type_information: str | None = None
        self._typed_class: Any = None
        self.lock = threading.Lock()
        self.out = sys.stdout
        #: the time -p prints: a bag message's receive time, else now
        self.stamp: Any = None

    def __call__(self, raw: Any) -> None:
        if self.done:
            return
        try:
            msg = self.decoder.decode(raw)
        except Exception as exc:
            self.error = str(exc)
            self.done = True
            return
        with self.lock:
            if self.done:
                return
            try:
                self._print(msg)
            except (BrokenPipeError, OSError):
                self.done = True
            except Exception as exc:  # a bad --filter expression or field: report once and stop
                self.error = f"{type(exc).__name__}: {exc}"
                self.done = True

    def _print(self, msg: Any) -> None:
        from minros.tools.echo import field_type, plot_header, plot_line, yaml_text

        if self.filter_fn is not None and not self.filter_fn(msg, self.real_topic):
            return
        if self.max_count is not None and self.count >= self.max_count:
            self.done = True
            return
        data = msg
        if self.getter is not None:
            if type(msg) is not self._typed_class:
                self._typed_class = type(msg)
                self.type_information = field_type(type(msg), self.field_path)
            data = self.getter(msg)
        if data is None:
            return
        self.count += 1
        now = self.stamp if self.stamp is not None else ros_now()
        offset = now if self.offset else None
        if self.plot:
            if self.first:
                self.out.write(plot_header(data, self.field_filter) + "\n")
                self.first = False
            text = plot_line(data, now, offset, self.field_filter)
        else:
            text = yaml_text(data, self.type_information, offset, self.transform, self.width)
        self.out.write(self.prefix + text + self.suffix + "\n")
        self.out.flush()
        if self.max_count is not None and self.count >= self.max_count:
            self.done = True


def echo_cmd(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] /topic")
    p.add_option("-b", "--bag", dest="bag", default=None, metavar="BAGFILE", help="echo messages from .bag file")
    p.add_option("-p", dest="plot", default=False, action="store_true", help="echo in a plotting friendly format")
    p.add_option("-w", dest="fixed_numeric_width", default=None, metavar="NUM_WIDTH",
                 help="fixed width for numeric values")
    p.add_option("--filter", dest="filter_expr", default=None, metavar="FILTER-EXPRESSION",
                 help="Python expression to filter messages that are printed. Expression can use "
                      "Python builtins as well as m (the message) and topic (the topic name).")
    p.add_option("--nostr", dest="nostr", default=False, action="store_true", help="exclude string fields")
    p.add_option("--noarr", dest="noarr", default=False, action="store_true", help="exclude arrays")
    p.add_option("-c", "--clear", dest="clear", default=False, action="store_true",
                 help="clear screen before printing next message")
    p.add_option("-a", "--all", dest="all_topics", default=False, action="store_true",
                 help="display all message in bag, only valid with -b option")
    p.add_option("-n", dest="msg_count", default=None, metavar="COUNT", help="number of messages to echo")
    p.add_option("--offset", dest="offset_time", default=False, action="store_true",
                 help="display time as offsets from current time (in seconds)")
    args, topics = p.parse_args(argv)
    # the checks in rostopic's order, so the same mistake gets the same message
    if len(topics) > 1:
        p.error("you may only specify one input topic")
    if args.all_topics and not args.bag:
        p.error("Display all option is only valid when echoing from bag files")
    if args.offset_time and args.bag:
        p.error("offset time option is not valid with bag files")
    if not topics and not args.all_topics:
        p.error("topic must be specified")
    try:
        args.msg_count = int(args.msg_count) if args.msg_count else None
    except ValueError:
        p.error("COUNT must be an integer")
    try:
        width = int(args.fixed_numeric_width) if args.fixed_numeric_width else None
    except ValueError:
        p.error("NUM_WIDTH must be an integer")
    if width is not None and width < 2:
        p.error("Fixed width for numeric values must be at least 2")
    args.fixed_numeric_width = width
    if args.bag:
        return _echo_bag(args.bag, resolve(NAME, topics[0]) if topics else None, args,
                         compile_filter(args.filter_expr))
    topic = resolve(NAME, topics[0])
    filter_fn = compile_filter(args.filter_expr)
    master = checked_master()
    init_tool_node()
    from minros.tools.echo import FieldError

    _type, real_topic, field_path = wait_topic_type(master, topic)
    try:
        echo = _Echo(topic.rstrip("/"), field_path, args, filter_fn, real_topic)
    except FieldError as exc:
        raise ToolError(str(exc)) from None
    from minros.client.topics import AnyMsg, Subscriber

    Subscriber(real_topic, AnyMsg, echo, queue_size=None)
    spin_until(lambda: echo.done)
    if echo.error:
        raise ToolError(echo.error)
    return 0
