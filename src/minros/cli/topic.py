"""``minros topic`` / ``rostopic``: list, info, type, find, echo, pub, hz, bw and delay.

Texts and exit statuses follow Debian's rostopic (ros_comm 1.15). ``echo``, ``hz`` and ``bw``
subscribe with md5 ``*`` and decode with the publisher's definition, so they work for types
that are not installed locally.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import threading
import time
from typing import Any, Callable, Dict, List, Tuple
from urllib.parse import urlparse

import yaml

from minros import names
from minros.tools.common import ToolError, dispatch, flush_stdout, option_parser, resolve, run_tool
from minros.tools.master import Master, MasterError

NAME = "rostopic"
USAGE = """rostopic is a command-line tool for printing information about ROS Topics.

Commands:
\trostopic bw\tdisplay bandwidth used by topic
\trostopic delay\tdisplay delay of topic from timestamp in header
\trostopic echo\tprint messages to screen
\trostopic find\tfind topics by type
\trostopic hz\tdisplay publishing rate of topic\x20\x20\x20\x20
\trostopic info\tprint information about active topic
\trostopic list\tlist active topics
\trostopic pub\tpublish data to topic
\trostopic type\tprint topic or field type

Type rostopic <command> -h for more detailed usage, e.g. 'rostopic echo -h'
"""
ONCE_DELAY = 3.0
SUBSCRIBER_TIMEOUT = 5.0


def _master() -> Master:
    return Master("/rostopic")


def _check_master() -> Master:
    master = _master()
    master.getPid()
    return master


# ---------------------------------------------------------------------------------------------
# graph queries

def get_topic_list(master: Master) -> Tuple[list, list]:
    pubs, subs, _srvs = master.system_state()
    types = dict((t, ty) for t, ty in master.topic_types())
    return ([(t, types.get(t, "unknown type"), nodes) for t, nodes in pubs],
            [(t, types.get(t, "unknown type"), nodes) for t, nodes in subs])


def _message_class(type_name: str) -> Any:
    from minros.msgs import get_message_class

    try:
        return get_message_class(type_name)
    except Exception:
        return None


def _nested_ok(cls: Any, path: str) -> bool:
    obj = cls()
    for part in path.split("/"):
        try:
            obj = getattr(obj, part)
        except AttributeError:
            return False
    return True


def topic_type(master: Master, topic: str) -> Tuple[str | None, str | None, str]:
    """(type, real topic, field path) for ``topic`` which may name a field (``/pose/x``)."""
    types = master.topic_types()
    for name, type_name in types:
        if name == topic:
            return (None if type_name == names.ANYTYPE else type_name), name, ""
    candidates = sorted(((t, ty) for t, ty in types if topic.startswith(t + "/")), reverse=True)
    for name, type_name in candidates:
        field = topic[len(name) + 1:].rstrip("/").split("[")[0]
        if field == "":
            break
        cls = _message_class(type_name)
        # a type not installed here is checked against its definition when messages arrive
        if cls is None or _nested_ok(cls, field):
            if type_name == names.ANYTYPE:
                return None, None, ""
            return type_name, name, topic[len(name):]
        continue
    return None, None, ""


def _field_error(master: Master, topic: str) -> str | None:
    """Why ``topic`` cannot be a field of a published topic of an installed type (or None)."""
    for name, type_name in sorted(master.topic_types(), reverse=True):
        if not topic.startswith(name + "/"):
            continue
        field = topic[len(name) + 1:].rstrip("/").split("[")[0]
        cls = _message_class(type_name)
        if field and cls is not None and not _nested_ok(cls, field):
            return f"no field named [{field}] in topic [{name}] of type [{type_name}]"
    return None


def wait_topic_type(master: Master, topic: str) -> Tuple[str, str, str]:
    found = topic_type(master, topic)
    if found[0]:
        return found  # type: ignore[return-value]
    # a misspelt field of a topic that exists is an error, not something to wait for
    problem = _field_error(master, topic)
    if problem:
        raise ToolError(problem)
    sys.stderr.write(f"WARNING: topic [{topic}] does not appear to be published yet\n")
    sys.stderr.flush()
    from minros import node

    while not node.is_shutdown():
        found = topic_type(master, topic)
        if found[0]:
            return found  # type: ignore[return-value]
        if node.wait_for_shutdown(0.1):
            break
    raise KeyboardInterrupt


def _init_node(disable_rosout: bool = False) -> None:
    from minros.client.init import init_node

    init_node(NAME, argv=[sys.argv[0]] + [a for a in sys.argv[1:] if ":=" in a],
              anonymous=True, disable_rosout=disable_rosout)


def _spin_until(done: Callable[[], bool], step: float = 0.1) -> None:
    from minros import node

    while not done():
        if node.wait_for_shutdown(step):
            return


# ---------------------------------------------------------------------------------------------
# list / info / type / find

def _print_list(master: Master, pubs: list, subs: list, pubs_only: bool, subs_only: bool,
                verbose: bool, indent: str = "") -> None:
    if verbose:
        if not subs_only:
            print(f"\n{indent}Published topics:")
            for t, ty, nodes in pubs:
                if len(nodes) > 1:
                    print(f"{indent} * {t} [{ty}] {len(nodes)} publishers")
                else:
                    print(f"{indent} * {t} [{ty}] 1 publisher")
        if not pubs_only:
            print(indent)
            print(f"{indent}Subscribed topics:")
            for t, ty, nodes in subs:
                if len(nodes) > 1:
                    print(f"{indent} * {t} [{ty}] {len(nodes)} subscribers")
                else:
                    print(f"{indent} * {t} [{ty}] 1 subscriber")
        print("")
        return
    if pubs_only:
        topics = [t for t, _, _ in pubs]
    elif subs_only:
        topics = [t for t, _, _ in subs]
    else:
        topics = list({t for t, _, _ in pubs} | {t for t, _, _ in subs})
    print("\n".join(f"{indent}{t}" for t in sorted(topics)))


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


def _list_bag(path: str, topic: str | None) -> int:
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


def _cmd_list(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [/namespace]")
    p.add_option("-b", "--bag", dest="bag", default=None, metavar="BAGFILE", help="list topics in .bag file")
    p.add_option("-v", "--verbose", dest="verbose", default=False, action="store_true",
                 help="list full details about each topic")
    p.add_option("-p", dest="publishers", default=False, action="store_true", help="list only publishers")
    p.add_option("-s", dest="subscribers", default=False, action="store_true", help="list only subscribers")
    p.add_option("--host", dest="hostname", default=False, action="store_true", help="group by host name")
    args, namespace = p.parse_args(argv)
    args.namespace = namespace
    if len(args.namespace) > 1:
        p.error("you may only specify one input topic")
    if args.bag:
        # the usage errors rostopic gives with a bag come first
        for flag, given in (("-s", args.subscribers), ("-p", args.publishers), ("--host", args.hostname)):
            if given:
                p.error(f"{flag} option is not valid with bags")
        return _list_bag(args.bag, resolve(NAME, args.namespace[0]) if args.namespace else None)
    if args.publishers and args.subscribers:
        p.error("you may only specify one of -p, -s")
    master = _master()
    pubs, subs = get_topic_list(master)
    if args.namespace:
        topic = resolve(NAME, args.namespace[0])
        ns = names.make_global_ns(topic)
        pubs = [x for x in pubs if x[0] == topic or x[0].startswith(ns)]
        subs = [x for x in subs if x[0] == topic or x[0].startswith(ns)]
    if not args.hostname:
        _print_list(master, pubs, subs, args.publishers, args.subscribers, args.verbose)
        return 0
    uris: Dict[str, str | None] = {}

    def by_host(entries: list) -> Dict[str, list]:
        out: Dict[str, list] = {}
        for t, ty, nodes in entries:
            for n in nodes:
                uri = master.lookup_node_cached(uris, n)
                host = urlparse(uri).hostname if uri else None
                rows = out.setdefault(str(host), [])
                match = [row for row in rows if row[0] == t]
                if match:
                    match[0][2].append(n)
                else:
                    rows.append((t, ty, [n]))
        return out

    host_pubs, host_subs = by_host(pubs), by_host(subs)
    for host in sorted(set(host_pubs) | set(host_subs)):
        hp, hs = host_pubs.get(host, []), host_subs.get(host, [])
        if (hp and not args.subscribers) or (hs and not args.publishers):
            print(f"Host [{host}]:")
            _print_list(master, hp, hs, args.publishers, args.subscribers, args.verbose, indent="  ")
    return 0


def info_text(master: Master, topic: str) -> str:
    pubs, subs = get_topic_list(master)
    pubs = [x for x in pubs if x[0] == topic]
    subs = [x for x in subs if x[0] == topic]
    if not pubs and not subs:
        raise ToolError(f"Unknown topic {topic}")
    types = dict((t, ty) for t, ty in master.topic_types())
    uris: Dict[str, str | None] = {}

    def api(n: str) -> str:
        return master.lookup_node_cached(uris, n) or f"unknown address {n}"

    out = f"Type: {types.get(topic, 'unknown type')}\n\n"
    if pubs:
        out += "Publishers: \n" + "".join(f" * {n} ({api(n)})\n" for _, _, nodes in pubs for n in nodes)
    else:
        out += "Publishers: None\n"
    out += "\n"
    if subs:
        out += "Subscribers: \n" + "".join(f" * {n} ({api(n)})\n" for _, _, nodes in subs for n in nodes)
    else:
        out += "Subscribers: None\n"
    return out + "\n"


def _one_topic(argv: List[str], prog: str, missing: str = "topic must be specified",
               many: str = "you may only specify one input topic") -> str:
    p = option_parser(prog, " /topic")
    _options, topics = p.parse_args(argv)
    if not topics:
        p.error(missing)
    if len(topics) > 1:
        p.error(many)
    return resolve(NAME, topics[0])


def _cmd_info(argv: List[str], prog: str) -> int:
    topic = _one_topic(argv, prog, "you must specify a topic name", "you may only specify one topic name")
    print(info_text(_master(), topic))
    return 0


def _cmd_type(argv: List[str], prog: str) -> int:
    # rostopic parses 'type' with argparse (its usage and errors name "rostopic type")
    p = argparse.ArgumentParser(prog=prog)
    p.add_argument("topic_or_field", help="Topic or field name")
    args = p.parse_args(argv)
    topic = resolve(NAME, args.topic_or_field)
    type_name, real, _field = topic_type(_master(), topic)
    if type_name is None:
        sys.stderr.write(f"unknown topic type [{topic}]\n")
        return 1
    if topic == real:
        print(type_name)
        return 0
    from minros.tools.echo import field_type

    field = topic[len(real) + 1:]
    cls = _message_class(type_name)
    ftype = field_type(cls, field) if cls is not None else None
    if ftype is None:
        sys.stderr.write(f"unknown topic type [{topic}]\n")
        return 1
    print(f"{type_name} {field} {ftype}")
    return 0


def _cmd_find(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " msg-type")
    _options, types = p.parse_args(argv)
    if not types:
        p.error("please specify a message type")
    if len(types) > 1:
        p.error("you may only specify one message type")
    print("\n".join(t for t, ty in _master().topic_types() if ty == types[0]))
    return 0


# ---------------------------------------------------------------------------------------------
# echo

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
        now = self.stamp if self.stamp is not None else _now()
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


def _now() -> Any:
    from minros.msgs import Time

    try:
        from minros.client import rostime

        return rostime.get_rostime()
    except Exception:
        return Time.from_sec(time.time())


def _compile_filter(expr: str | None) -> Callable | None:
    if not expr:
        return None
    try:
        code = compile(expr, "<filter>", "eval")
    except SyntaxError as exc:
        raise ToolError(f"invalid filter expression [{expr}]: {exc.msg}") from None

    def fn(m: Any, topic: str) -> bool:
        return bool(eval(code, {"__builtins__": __builtins__}, {"m": m, "topic": topic}))  # noqa: S307 - rostopic's documented --filter

    return fn


def _cmd_echo(argv: List[str], prog: str) -> int:
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
                         _compile_filter(args.filter_expr))
    topic = resolve(NAME, topics[0])
    filter_fn = _compile_filter(args.filter_expr)
    master = _check_master()
    _init_node()
    from minros.tools.echo import FieldError

    _type, real_topic, field_path = wait_topic_type(master, topic)
    try:
        echo = _Echo(topic.rstrip("/"), field_path, args, filter_fn, real_topic)
    except FieldError as exc:
        raise ToolError(str(exc)) from None
    from minros.client.topics import AnyMsg, Subscriber

    Subscriber(real_topic, AnyMsg, echo, queue_size=None)
    _spin_until(lambda: echo.done)
    if echo.error:
        raise ToolError(echo.error)
    return 0


# ---------------------------------------------------------------------------------------------
# hz / bw / delay

class HzStats:
    """Message inter-arrival statistics over a window (rostopic hz)."""

    def __init__(self, window_size: int = -1) -> None:
        self.window = window_size if window_size >= 0 else 50000
        self.lock = threading.Lock()
        self.t0 = -1.0
        self.tn = 0.0
        self.last_printed = 0.0
        self.times: List[float] = []

    def tick(self, now: float) -> None:
        with self.lock:
            if self.t0 < 0 or self.t0 > now:
                self.t0 = self.tn = now
                self.times = []
            else:
                self.times.append(now - self.tn)
                self.tn = now
            if len(self.times) > self.window - 1:
                del self.times[0:len(self.times) - max(self.window - 1, 0)]

    def get(self) -> Tuple[float, float, float, float, int] | None:
        with self.lock:
            if not self.times or self.tn == self.last_printed:
                return None
            n = len(self.times)
            mean = sum(self.times) / n
            rate = 1.0 / mean if mean > 0.0 else 0.0
            std = math.sqrt(sum((x - mean) ** 2 for x in self.times) / n)
            self.last_printed = self.tn
            return rate, min(self.times), max(self.times), std, n + 1


def _ascii_table(header: List[str], cols: Dict[str, List[str]]) -> str:
    widths = []
    aligned = []
    for h in header:
        width = max(len(h), max(len(c) for c in cols[h]))
        widths.append(width)
        aligned.append(h.center(width))
        cols[h] = [c.ljust(width) for c in cols[h]]
    total = sum(widths) + 3 * (len(header) - 1)
    rows = len(cols[header[0]])
    body = "\n".join("   ".join(cols[h][i] for h in header) for i in range(rows))
    return "{}\n{}\n{}\n".format("   ".join(aligned), "=" * total, body)


def _use_sim_time(master: Master) -> bool:
    try:
        return bool(master.getParam("/use_sim_time"))
    except MasterError:
        return False


def _cmd_hz(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] /topic_0 [/topic_1 [topic_2 [..]]]")
    p.add_option("-w", "--window", dest="window_size", default="-1", metavar="WINDOW",
                 help="window size, in # of messages, for calculating rate")
    p.add_option("--filter", dest="filter_expr", default=None, metavar="EXPR",
                 help="only measure messages matching the specified Python expression")
    p.add_option("--wall-time", dest="use_wtime", default=False, action="store_true",
                 help="calculates rate using wall time which can be helpful when clock isn't published during simulation")
    p.add_option("--tcpnodelay", dest="tcp_nodelay", default=False, action="store_true",
                 help="use the TCP_NODELAY transport hint when subscribing to topics")
    args, names_given = p.parse_args(argv)
    if not names_given:
        p.error("topic must be specified")
    try:
        window = int(args.window_size)
    except ValueError:
        p.error("window size must be an integer")
    topics = [resolve(NAME, t) for t in names_given]
    filter_fn = _compile_filter(args.filter_expr)
    master = _check_master()
    _init_node()
    from minros.client.topics import AnyMsg, Subscriber
    from minros.tools.decode import Decoder

    sim = _use_sim_time(master) and not args.use_wtime
    stats = {t: HzStats(window) for t in topics}
    decoder = Decoder()
    for topic in topics:
        _type, real_topic, _field = wait_topic_type(master, topic)

        def callback(raw: Any, topic: str = topic) -> None:
            if filter_fn is not None:
                try:
                    if not filter_fn(decoder.decode(raw), topic):
                        return
                except Exception:
                    return
            stats[topic].tick(_now().to_sec() if sim else time.time())

        Subscriber(real_topic, AnyMsg, callback, tcp_nodelay=args.tcp_nodelay)
        print(f"subscribed to [{real_topic}]")
    if sim:
        sys.stderr.write("WARNING: may be using simulated time\n")
    flush_stdout()
    from minros import node

    while not node.wait_for_shutdown(1.0):
        if len(topics) == 1:
            result = stats[topics[0]].get()
            if result is None:
                print("no new messages")
            else:
                rate, mn, mx, std, n = result
                print(f"average rate: {rate:.3f}\n\tmin: {mn:.3f}s max: {mx:.3f}s std dev: {std:.5f}s window: {n}")
        else:
            header = ["topic", "rate", "min_delta", "max_delta", "std_dev", "window"]
            cols: Dict[str, List[str]] = {h: [] for h in header}
            for topic in topics:
                result = stats[topic].get()
                if result is None:
                    continue
                rate, mn, mx, std, n = result
                cols["topic"].append(topic)
                cols["rate"].append(f"{rate:.4}")
                cols["min_delta"].append(f"{mn:.4}")
                cols["max_delta"].append(f"{mx:.4}")
                cols["std_dev"].append(f"{std:.4}")
                cols["window"].append(str(n))
            print(_ascii_table(header, cols) if cols["topic"] else "no new messages")
        flush_stdout()
    return 0


def _format_bw(sizes: List[int], times: List[float], now: float) -> str | None:
    n = len(times)
    if n < 2:
        return None
    total = sum(sizes)
    per_s = total / (now - times[0])
    mean = total / n
    values = [per_s, mean, min(sizes), max(sizes)]
    if per_s < 1000:
        bw, mean_s, min_s, max_s = [f"{v:.2f}B" for v in values]
    elif per_s < 1000000:
        bw, mean_s, min_s, max_s = ["%.2fKB" % (v / 1000) for v in values]
    else:
        bw, mean_s, min_s, max_s = ["%.2fMB" % (v / 1000000) for v in values]
    return f"average: {bw}/s\n\tmean: {mean_s} min: {min_s} max: {max_s} window: {n}"


def _cmd_bw(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " /topic")
    p.add_option("-w", "--window", dest="window_size", default=None, metavar="WINDOW",
                 help="window size, in # of messages, for calculating rate")
    args, topics = p.parse_args(argv)
    if not topics:
        p.error("topic must be specified")
    if len(topics) > 1:
        p.error("you may only specify one input topic")
    try:
        window = int(args.window_size) if args.window_size is not None else 100
    except ValueError:
        p.error("window size must be an integer")
    window = window or 100
    topic = resolve(NAME, topics[0])
    master = _check_master()
    _type, real_topic, _field = wait_topic_type(master, topic)
    _init_node()
    from minros.client.topics import AnyMsg, Subscriber

    lock = threading.Lock()
    sizes: List[int] = []
    times: List[float] = []

    def callback(raw: Any) -> None:
        with lock:
            times.append(time.time())
            sizes.append(len(raw._buff))
            if len(times) > window:
                del times[0]
                del sizes[0]

    Subscriber(real_topic, AnyMsg, callback)
    print(f"subscribed to [{real_topic}]")
    flush_stdout()
    from minros import node

    while not node.wait_for_shutdown(1.0):
        with lock:
            text = _format_bw(list(sizes), list(times), time.time())
        if text:
            print(text)
            flush_stdout()
    return 0


def _cmd_delay(argv: List[str], prog: str) -> int:
    # rostopic parses 'delay' with argparse, its errors naming only the tool
    tool = prog.rsplit(" ", 1)[0]
    p = argparse.ArgumentParser(usage=f"{prog} [options] /topic", prog=tool)
    p.add_argument("topic", help="topic name to be calcurated the delay")
    p.add_argument("-w", "--window", dest="window_size", default=-1, type=int,
                   help="window size, in # of messages, for calculating rate")
    p.add_argument("--tcpnodelay", dest="tcp_nodelay", action="store_true",
                   help="use the TCP_NODELAY transport hint when subscribing to topics")
    args = p.parse_args(argv)
    topic = resolve(NAME, args.topic)
    master = _check_master()
    _type, real_topic, _field = wait_topic_type(master, topic)
    _init_node()
    from minros.client.topics import AnyMsg, Subscriber
    from minros.tools.decode import Decoder

    decoder = Decoder()
    window = args.window_size if args.window_size >= 0 else 50000
    lock = threading.Lock()
    delays: List[float] = []
    state = {"t0": -1.0, "tn": 0.0, "last": 0.0, "warned": False}

    def callback(raw: Any) -> None:
        msg = decoder.decode(raw)
        if not getattr(msg, "_has_header", False):
            if not state["warned"]:
                sys.stderr.write("msg does not have header\n")
                state["warned"] = True
            return
        now = _now()
        with lock:
            cur = now.to_sec()
            if state["t0"] < 0 or state["t0"] > cur:
                state["t0"] = state["tn"] = cur
                delays.clear()
            else:
                delays.append(cur - msg.header.stamp.to_sec())
                state["tn"] = cur
            if len(delays) > window - 1:
                del delays[0]

    Subscriber(real_topic, AnyMsg, callback, tcp_nodelay=args.tcp_nodelay)
    print(f"subscribed to [{real_topic}]")
    flush_stdout()
    from minros import node

    while not node.wait_for_shutdown(1.0):
        with lock:
            if not delays:
                continue
            if state["tn"] == state["last"]:
                print("no new messages")
                continue
            n = len(delays)
            mean = sum(delays) / n
            std = math.sqrt(sum((x - mean) ** 2 for x in delays) / n)
            state["last"] = state["tn"]
            text = (f"average delay: {mean:.3f}\n\tmin: {min(delays):.3f}s max: {max(delays):.3f}s "
                    f"std dev: {std:.5f}s window: {n + 1}")
        print(text)
        flush_stdout()
    return 0


# ---------------------------------------------------------------------------------------------
# pub

def _fill(msg_class: Any, pub_args: list) -> Any:
    from minros.exceptions import MessageException
    from minros.msgs.fill import fill_message_args, printable_message_args, substitution_keys

    msg = msg_class()
    try:
        fill_message_args(msg, pub_args, substitution_keys(_now()))
    except (MessageException, ValueError, TypeError) as exc:
        raise ToolError(" ".join(str(exc).split()) + f" (Args are: [{printable_message_args(msg)}])") from None
    try:
        msg.serialize_to_bytes()
    except MessageException as exc:
        raise ToolError("Unable to publish message. One of the fields has an incorrect type: "
                        + " ".join(str(exc).split())) from None
    return msg


def _file_documents(path: str) -> List[Any]:
    if not os.path.isfile(path):
        raise ToolError(f"file does not exist: {path}")
    try:
        with open(path) as f:
            return [d for d in yaml.safe_load_all(f)]
    except yaml.YAMLError as exc:
        raise ToolError("invalid YAML in file: " + " ".join(str(exc).split())) from None


def _stdin_lines() -> Any:
    """Lines of stdin; stops at EOF or when the node shuts down (Ctrl-C while waiting).

    Reads the file descriptor directly: a buffered reader could hold lines that select()
    no longer reports as readable."""
    import select

    from minros import node

    try:
        fd = sys.stdin.fileno()
    except (AttributeError, OSError, ValueError):
        yield from sys.stdin
        return
    pending = b""
    while not node.is_shutdown():
        ready, _, _ = select.select([fd], [], [], 0.5)
        if not ready:
            continue
        chunk = os.read(fd, 65536)
        if not chunk:
            break
        pending += chunk
        *lines, pending = pending.split(b"\n")
        for line in lines:
            yield line.decode("utf-8", "replace") + "\n"
    if pending:
        yield pending.decode("utf-8", "replace")


def _stdin_document(text: str) -> Any:
    """The one document in ``text`` (nothing if empty); invalid YAML is reported and skipped."""
    try:
        loaded = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        sys.stderr.write("Invalid YAML: " + " ".join(str(exc).split()) + "\n")
        return
    if loaded is not None:
        yield loaded


def _stdin_documents() -> Any:
    buff: List[str] = []
    for line in _stdin_lines():
        if line.strip() == "---":
            text = "".join(buff).rstrip()
            buff = []
            yield from _stdin_document(text)
        else:
            buff.append(line)
    text = "".join(buff).strip()
    if text:
        yield from _stdin_document(text)


def _cmd_pub(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " /topic type [args...]")
    p.add_option("-v", dest="verbose", default=False, action="store_true", help="print verbose output")
    p.add_option("-r", "--rate", dest="rate", default=None,
                 help="publishing rate (hz).  For -f and stdin input, this defaults to 10.  Otherwise it is not set.")
    p.add_option("-1", "--once", dest="once", default=False, action="store_true",
                 help="publish one message and exit")
    p.add_option("-f", "--file", dest="file", default=None, metavar="FILE", help="read args from YAML file (Bagy)")
    p.add_option("-l", "--latch", dest="latch", default=False, action="store_true",
                 help="enable latching for -f, -r and piped input.  This latches the first message.")
    p.add_option("-s", "--substitute-keywords", dest="substitute_keywords", default=False, action="store_true",
                 help="When publishing with a rate, performs keyword ('now' or 'auto') substitution for each message")
    p.add_option("--use-rostime", dest="use_rostime", default=False, action="store_true",
                 help="use rostime for time stamps, else walltime is used")
    # negative numbers such as -7 or -0.5 are message values, not options ('-1' is --once, as in
    # rostopic; '--' ends the options)
    options: List[str] = []
    positional: List[str] = []
    takes_value = {"-r", "--rate", "-f", "--file"}
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--":
            positional.extend(argv[i + 1:])
            break
        if not a.startswith("-") or a == "-" or (a[1:2].isdigit() and a != "-1") or a[1:2] == ".":
            positional.append(a)
        else:
            options.append(a)
            if a in takes_value and i + 1 < len(argv):
                options.append(argv[i + 1])
                i += 1
        i += 1
    args, _none = p.parse_args(options)
    rate: float | None = None
    if args.rate is not None:
        if args.once:
            p.error("You cannot select both -r and -1 (--once)")
        try:
            rate = float(args.rate)
        except ValueError:
            p.error("rate must be a number")
        if rate <= 0:
            p.error("rate must be greater than zero")
    if not positional:
        p.error("/topic must be specified")
    if len(positional) == 1:
        p.error("topic type must be specified")
    if len(positional) > 2 and args.file:
        p.error("args conflict with -f setting")
    topic, type_name = resolve(NAME, positional[0]), positional[1]
    pub_args = []
    for text in positional[2:]:
        try:
            pub_args.append(yaml.safe_load(text))
        except yaml.YAMLError as exc:
            p.error("Argument error: " + " ".join(str(exc).split()))
    from minros.msgs import UnknownTypeError, get_message_class

    try:
        msg_class = get_message_class(type_name)
    except (UnknownTypeError, ValueError, LookupError):
        pkg = type_name.split("/")[0] if "/" in type_name else None
        raise ToolError(f"invalid message type: {type_name}. If this is a valid message type, "
                        f"perhaps you need to type 'rosmake {pkg}'") from None
    _check_master()
    latch = rate is None or args.latch
    msg: Any = None
    if pub_args or not msg_class.__slots__:
        msg = _fill(msg_class, pub_args)  # reject bad values before registering anything
    elif not args.file and sys.stdin.isatty():
        p.error("Please specify message values")
    from minros import node
    from minros.client.topics import Publisher

    _init_node(disable_rosout=True)
    pub = Publisher(topic, msg_class, latch=latch, queue_size=100)
    if msg is not None:
        _publish_args(pub, msg_class, msg, pub_args, rate, args)
        return 0
    # documents from -f FILE or stdin
    if rate is None and not args.latch and not args.once:
        rate = 10.0
    docs = _file_documents(args.file) if args.file else None
    deadline = time.time() + SUBSCRIBER_TIMEOUT
    while pub.get_num_connections() == 0 and time.time() < deadline:
        if node.wait_for_shutdown(0.01):
            return 0
    if docs is not None and len(docs) == 1 and rate is not None:
        print("Got one message and a rate, publishing repeatedly")
        doc = docs[0]
        _publish_args(pub, msg_class, _fill(msg_class, doc if isinstance(doc, list) else [doc]),
                      doc if isinstance(doc, list) else [doc], rate, args)
        return 0
    period = 1.0 / rate if rate else None
    for doc in (docs if docs is not None else _stdin_documents()):
        if node.is_shutdown():
            break
        if doc is None:
            continue
        doc_args = doc if isinstance(doc, list) else [doc]
        m = _fill(msg_class, doc_args)
        if args.verbose:
            print(f"publishing {m}")
        pub.publish(m)
        if args.once:
            break
        if period and node.wait_for_shutdown(period):
            break
    if latch and not node.is_shutdown():
        node.wait_for_shutdown(ONCE_DELAY if args.once else 0.5)
    return 0


def _publish_args(pub: Any, msg_class: Any, msg: Any, pub_args: list, rate: float | None, args: Any) -> None:
    from minros import node

    if rate is None:
        text = f"publishing and latching [{msg}]" if args.verbose else "publishing and latching message"
        text += f" for {ONCE_DELAY} seconds" if args.once else ". Press ctrl-C to terminate"
        print(text)
        flush_stdout()
        pub.publish(msg)
        if args.once:
            node.wait_for_shutdown(ONCE_DELAY)
        else:
            node.wait_for_shutdown(None)
        return
    period = 1.0 / rate
    next_time = time.monotonic()
    while not node.is_shutdown():
        if args.substitute_keywords:
            msg = _fill(msg_class, pub_args)
        if args.verbose:
            print(f"publishing {msg}")
            flush_stdout()
        pub.publish(msg)
        next_time += period
        delay = next_time - time.monotonic()
        if delay < -period:  # fell behind (slow consumer): do not burst to catch up
            next_time = time.monotonic()
            delay = 0
        if node.wait_for_shutdown(max(delay, 0.0)):
            break


COMMANDS = {"list": _cmd_list, "info": _cmd_info, "type": _cmd_type, "find": _cmd_find,
            "echo": _cmd_echo, "pub": _cmd_pub, "hz": _cmd_hz, "bw": _cmd_bw, "delay": _cmd_delay}


def main(argv: List[str], prog: str = "rostopic") -> int:
    if argv[:1] in (["-h"], ["--help"]):
        # rostopic has no -h of its own: like any unknown command, the usage and EX_USAGE
        print(USAGE)
        return 64
    return run_tool(lambda: dispatch(argv, prog, COMMANDS, USAGE, usage_status=64))


# ---------------------------------------------------------------------------------------------
# the Python API of ROS's rostopic module (the stand-in re-exports it): the same code as the
# commands, with rostopic's exceptions instead of exit statuses


class ROSTopicException(Exception):
    """A rostopic call failed (unknown topic, type not installed, ...)."""


class ROSTopicIOException(ROSTopicException):
    """The master (or a node) could not be reached."""


def _library(fn: Callable[[], Any]) -> Any:
    from minros.tools.common import library_call

    return library_call(fn, ROSTopicException, ROSTopicIOException)


def msgevalgen(pattern: str) -> Callable[[Any], Any] | None:
    """A function message -> the field ``pattern`` names (``/pose/position/x``), or None (and,
    as rostopic's, the reason on stderr when the pattern is malformed: ``/vals[0``)."""
    from minros.tools.echo import FieldError, make_field_getter

    if not pattern:
        return None
    try:
        return make_field_getter(pattern)
    except FieldError as exc:
        print(exc, file=sys.stderr)
        return None


def str_plot_fields(val: Any, f: str, field_filter: Callable | None) -> str:
    """rostopic's ``-p`` CSV header for message ``val``, its fields named from ``f``
    (``time,field.x,field.y``)."""
    from minros.tools.echo import plot_fields

    return "time," + (plot_fields(val, f, field_filter) or "")


def str_plot(val: Any, time_offset: Any = None, current_time: Any = None,
             field_filter: Callable | None = None, type_information: str | None = None,
             fixed_numeric_width: int | None = None, value_transform: Callable | None = None) -> str:
    """rostopic's ``-p`` CSV line for message ``val``: the time in ns (``current_time``, else
    the header's stamp, else now; less ``time_offset``), then every field's value."""
    from minros.tools.echo import plot_line

    if current_time is not None:
        return plot_line(val, current_time, time_offset, field_filter, header_first=False)
    return plot_line(val, _now(), time_offset, field_filter)


def get_topic_type(topic: str, blocking: bool = False) -> Tuple[str | None, str | None, Any]:
    """``(type, topic, field evaluator)`` of a topic or of a field of one (``/odom/pose``);
    ``(None, None, None)`` when nobody publishes it, unless ``blocking`` waits for it."""
    def run() -> Tuple[str | None, str | None, Any]:
        master = _master()
        resolved = resolve(NAME, topic)
        type_name, real, field = topic_type(master, resolved)
        if type_name is None and blocking:
            type_name, real, field = wait_topic_type(master, resolved)
        if type_name is None:
            return None, None, None
        return type_name, real, msgevalgen(field)

    return _library(run)


def get_topic_class(topic: str, blocking: bool = False) -> Tuple[Any, str | None, Any]:
    """``(message class, topic, field evaluator)``, as :func:`get_topic_type`."""
    type_name, real, evaluator = get_topic_type(topic, blocking)
    if type_name is None:
        return None, None, None
    cls = _message_class(type_name)
    if cls is None:
        raise ROSTopicException(f"Cannot load message class for [{type_name}]. "
                                "Are your messages built?")
    return cls, real, evaluator


def get_info_text(topic: str) -> str:
    """What ``rostopic info TOPIC`` prints."""
    return _library(lambda: info_text(_master(), resolve(NAME, topic)))


class ROSTopicHz:
    """Publishing-rate statistics fed by a subscriber callback (rostopic's ROSTopicHz):
    ``rospy.Subscriber(topic, rospy.AnyMsg, hz.callback_hz, callback_args=topic)``."""

    def __init__(self, window_size: int, filter_expr: Callable | None = None,
                 use_wtime: bool = False) -> None:
        self.window_size = window_size
        self.filter_expr = filter_expr
        self.use_wtime = use_wtime
        self._stats: Dict[str | None, HzStats] = {}
        self._lock = threading.Lock()

    def _for(self, topic: str | None) -> HzStats:
        with self._lock:
            stats = self._stats.get(topic)
            if stats is None:
                stats = self._stats[topic] = HzStats(self.window_size)
            return stats

    def callback_hz(self, m: Any, topic: str | None = None) -> None:
        if self.filter_expr is not None and not self.filter_expr(m):
            return
        self._for(topic).tick(time.time() if self.use_wtime else _now().to_sec())

    def get_hz(self, topic: str | None = None) -> Tuple[float, float, float, float, int] | None:
        """``(rate, min delta, max delta, std dev, window)`` since the last call, or None."""
        return self._for(topic).get()

    def print_hz(self, topics: Tuple[str | None, ...] = (None,)) -> None:
        for topic in topics:
            result = self.get_hz(topic)
            if result is None:
                print("no new messages")
                continue
            rate, mn, mx, std, n = result
            print(f"average rate: {rate:.3f}\n\tmin: {mn:.3f}s max: {mx:.3f}s "
                  f"std dev: {std:.5f}s window: {n}")


def rostopicmain(argv: List[str] | None = None) -> None:
    """The rostopic command (``argv`` as sys.argv, program name first)."""
    sys.exit(main(list(sys.argv if argv is None else argv)[1:]))


# -- more of rostopic's Python API: the helpers its commands are built from, which tools and
# scripts call directly (rostopic._get_topic_type to find an action's type, ROSTopicBandwidth
# in monitors, create_publisher for dynamic publishing, CallbackEcho for echo-like output)

_CALLER_APIS: Dict[str, str] = {}


def check_master_api() -> None:
    """rostopic._check_master: raise :class:`ROSTopicIOException` when no master answers."""
    _library(lambda: _check_master() and None)


def master_get_topic_types_api(master: Any) -> List[List[str]]:
    """rostopic._master_get_topic_types: ``getTopicTypes`` (``getPublishedTopics`` from an old
    master)."""
    if isinstance(master, Master):
        return master.topic_types()
    return master.getTopicTypes()


def get_topic_type_now(topic: str) -> Tuple[str | None, str | None, Any]:
    """rostopic._get_topic_type: ``(type, real topic, field evaluator)`` as published now,
    ``(None, None, None)`` when nobody publishes it; the name is used as given."""
    def run() -> Tuple[str | None, str | None, Any]:
        type_name, real, field = topic_type(_master(), topic)
        if type_name is None:
            return None, None, None
        return type_name, real, msgevalgen(field)

    return _library(run)


def get_nested_attribute(msg: Any, nested_attributes: str) -> Any:
    """rostopic._get_nested_attribute: ``msg.a.b`` for ``'a/b'`` (AttributeError if absent)."""
    value = msg
    for attr in nested_attributes.split("/"):
        value = getattr(value, attr)
    return value


def get_api(master: Any, caller_id: str) -> str:
    """The XML-RPC URI of node ``caller_id`` (cached), ``'unknown address <node>'`` when the
    master does not know it."""
    cached = _CALLER_APIS.get(caller_id)
    if cached:
        return cached

    def run() -> str:
        try:
            uri = master.lookupNode(caller_id)
        except MasterError:
            return f"unknown address {caller_id}"
        _CALLER_APIS[caller_id] = uri
        return uri

    try:
        return _library(run)
    except ROSTopicIOException:
        raise
    except ROSTopicException:  # the master refused the name: as rosgraph's MasterError
        return f"unknown address {caller_id}"


def get_topic_list_api(master: Any = None) -> Tuple[list, list]:
    """``([(topic, type, [publisher...])...], [(topic, type, [subscriber...])...])``."""
    return _library(lambda: get_topic_list(master if isinstance(master, Master) else _master()))


def find_by_type(topic_type: str) -> List[str]:
    """The topics published with type ``topic_type`` (``rostopic find``)."""
    return _library(lambda: [t for t, ty in _master().topic_types() if ty == topic_type])


def create_value_transform(echo_nostr: bool, echo_noarr: bool) -> Callable[..., Any]:
    """``fn(value, type_information=None)``: strings and arrays replaced by a note of their
    length, as ``rostopic echo --nostr/--noarr`` prints them."""
    from minros.tools.echo import make_value_transform

    transform = make_value_transform(echo_nostr, echo_noarr)
    if transform is None:
        return lambda val, type_information=None: val
    return transform


def create_field_filter(echo_nostr: bool, echo_noarr: bool) -> Callable[[Any], Any]:
    """``fn(message) -> field names`` without strings and/or arrays (``echo -p --nostr``)."""
    from minros.tools.echo import make_field_filter

    return make_field_filter(echo_nostr, echo_noarr)


class CallbackEcho:
    """rostopic echo's printer: ``callback(msg, {'topic': ..., 'type_information': ...})``
    writes the message as YAML (or CSV with ``plot``) to stdout, ``---`` between messages,
    until ``count`` messages have been printed (then ``done``)."""

    def __init__(self, topic: str, msg_eval: Callable | None, plot: bool = False,
                 filter_fn: Callable | None = None, echo_clear: bool = False,
                 echo_all_topics: bool = False, offset_time: bool = False,
                 count: int | None = None, field_filter_fn: Callable | None = None,
                 fixed_numeric_width: int | None = None,
                 value_transform_fn: Callable | None = None) -> None:
        self.topic = topic[:-1] if topic and topic.endswith("/") else topic
        self.msg_eval = msg_eval
        self.plot = plot
        self.filter_fn = filter_fn
        self.fixed_numeric_width = fixed_numeric_width
        self.prefix = "\033[2J\033[;H" if echo_clear and not plot else ""
        self.suffix = "" if plot else "\n---"
        self.echo_all_topics = echo_all_topics
        self.offset_time = offset_time
        self.done = False
        self.max_count = count
        self.count = 0
        self.field_filter = field_filter_fn
        self.value_transform = value_transform_fn
        self.first = True
        self.last_topic: str | None = None
        self.last_msg_eval: Callable | None = None

    def custom_strify_message(self, val: Any, indent: str = "", time_offset: Any = None,
                              current_time: Any = None, field_filter: Callable | None = None,
                              type_information: str | None = None,
                              fixed_numeric_width: int | None = None,
                              value_transform: Callable | None = None) -> str:
        from minros.tools.echo import yaml_text

        return yaml_text(val, type_information, time_offset, value_transform, fixed_numeric_width)

    def str_fn(self, data: Any, time_offset: Any = None, current_time: Any = None,
               field_filter: Callable | None = None, type_information: str | None = None,
               fixed_numeric_width: int | None = None, value_transform: Callable | None = None) -> str:
        if not self.plot:
            return self.custom_strify_message(
                data, time_offset=time_offset, current_time=current_time,
                field_filter=field_filter, type_information=type_information,
                fixed_numeric_width=fixed_numeric_width, value_transform=value_transform)
        return str_plot(data, time_offset, current_time, field_filter)

    def callback(self, data: Any, callback_args: Dict[str, Any], current_time: Any = None) -> None:
        """Print ``data`` received on ``callback_args['topic']`` (a bag's time as
        ``current_time``)."""
        topic = callback_args["topic"]
        type_information = callback_args.get("type_information")
        if self.filter_fn is not None and not self.filter_fn(data):
            return
        if self.max_count is not None and self.count >= self.max_count:
            self.done = True
            return
        msg_eval = self.msg_eval
        if topic != self.topic:
            if self.topic.startswith(topic + "/"):  # self.topic names a field of topic
                if topic != self.last_topic:
                    self.last_msg_eval = msgevalgen(self.topic[len(topic):])
                    self.last_topic = topic
                msg_eval = self.last_msg_eval
            elif not self.echo_all_topics:
                return
        try:
            if msg_eval is not None:
                data = msg_eval(data)
            if data is not None:
                from minros.tools.echo import plot_header

                self.count += 1
                if self.plot and self.first:
                    sys.stdout.write(plot_header(data, self.field_filter) + "\n")
                    self.first = False
                offset = _now() if self.offset_time else None
                sys.stdout.write(self.prefix + self.str_fn(
                    data, time_offset=offset, current_time=current_time,
                    field_filter=self.field_filter, type_information=type_information,
                    fixed_numeric_width=self.fixed_numeric_width,
                    value_transform=self.value_transform) + self.suffix + "\n")
                sys.stdout.flush()
            if self.max_count is not None and self.count >= self.max_count:
                self.done = True
        except OSError:  # stdout closed (a pipe to head)
            self.done = True


class ROSTopicBandwidth:
    """Received bandwidth of a topic (rostopic bw): subscribe with ``rospy.AnyMsg`` and
    ``callback``; ``print_bw()`` prints the average over the last ``window_size`` messages."""

    def __init__(self, window_size: int = 100) -> None:
        self.lock = threading.Lock()
        self.last_printed_tn = 0
        self.sizes: List[int] = []
        self.times: List[float] = []
        self.window_size = window_size or 100

    def callback(self, data: Any) -> None:
        with self.lock:
            self.times.append(time.time())
            self.sizes.append(len(data._buff))
            if len(self.times) > self.window_size:
                del self.times[0]
                del self.sizes[0]

    def get_bw_text(self) -> str | None:
        """What ``print_bw`` prints (None before two messages)."""
        with self.lock:
            return _format_bw(list(self.sizes), list(self.times), time.time())

    def print_bw(self) -> None:
        text = self.get_bw_text()
        if text is not None:
            print(text)


class ROSTopicDelay:
    """Delay between a message's header stamp and its arrival (rostopic delay): subscribe
    with the topic's class and ``callback_delay``."""

    def __init__(self, window_size: int) -> None:
        self.lock = threading.Lock()
        self.last_msg_tn = 0.0
        self.msg_t0 = -1.0
        self.msg_tn = 0.0
        self.delays: List[float] = []
        self.window_size = window_size if window_size >= 0 else 50000

    def callback_delay(self, msg: Any) -> None:
        if not getattr(msg, "_has_header", False):
            from minros.client.log import logerr

            logerr("msg does not have header")
            return
        with self.lock:
            now = _now()
            if now.is_zero():  # simulated time restarted
                if self.delays:
                    print("time has reset, resetting counters")
                    self.delays = []
                return
            cur = now.to_sec()
            if self.msg_t0 < 0 or self.msg_t0 > cur:
                self.msg_t0 = self.msg_tn = cur
                self.delays = []
            else:
                self.delays.append(cur - msg.header.stamp.to_sec())
                self.msg_tn = cur
            if len(self.delays) > self.window_size - 1:
                del self.delays[0]

    def get_delay(self) -> Tuple[float, float, float, float, int] | None:
        """``(mean, min, max, std dev, window)`` since the last call, or None."""
        if self.msg_tn == self.last_msg_tn:
            return None
        with self.lock:
            if not self.delays:
                return None
            n = len(self.delays)
            mean = sum(self.delays) / n
            std = math.sqrt(sum((x - mean) ** 2 for x in self.delays) / n)
            self.last_msg_tn = self.msg_tn
            return mean, min(self.delays), max(self.delays), std, n + 1

    def print_delay(self) -> None:
        if not self.delays:
            return
        result = self.get_delay()
        if result is None:
            print("no new messages")
            return
        mean, mn, mx, std, n = result
        print(f"average delay: {mean:.3f}\n\tmin: {mn:.3f}s max: {mx:.3f}s std dev: {std:.5f}s "
              f"window: {n}")


def create_publisher(topic_name: str, topic_type: str, latch: bool,
                     disable_rostime: bool = True) -> Tuple[Any, Any]:
    """``(Publisher, message class)`` for a topic and type given as strings; initialises this
    process as an anonymous ``rostopic`` node without /rosout, as rostopic pub does."""
    from minros.client.init import init_node
    from minros.client.topics import Publisher
    from minros.msgs import UnknownTypeError, get_message_class

    topic = names.script_resolve_name(NAME, topic_name)
    try:
        msg_class = get_message_class(topic_type)
    except (UnknownTypeError, LookupError):
        package = topic_type.split("/")[0] if "/" in topic_type else None
        raise ROSTopicException(f"invalid message type: {topic_type}.\nIf this is a valid message "
                                f"type, perhaps you need to type 'rosmake {package}'") from None
    except ValueError:
        raise ROSTopicException(f"invalid topic type: {topic_type}") from None
    init_node(NAME, anonymous=True, disable_rosout=True, disable_rostime=disable_rostime)
    return Publisher(topic, msg_class, latch=latch, queue_size=100), msg_class


def publish_message(pub: Any, msg_class: Any, pub_args: Any, rate: float | None = None,
                    once: bool = False, verbose: bool = False,
                    substitute_keywords: bool = False) -> None:
    """Fill a ``msg_class`` from YAML-loaded ``pub_args`` and publish it: latched (and kept
    until shutdown unless ``once``), or every 1/``rate`` s until shutdown."""
    from minros import node

    msg = _library(lambda: _fill(msg_class, pub_args))
    if rate is None:
        text = f"publishing and latching [{msg}]" if verbose else "publishing and latching message"
        print(text + (f" for {ONCE_DELAY} seconds" if once else ". Press ctrl-C to terminate"))
        flush_stdout()
        pub.publish(msg)
        if not once:
            node.wait_for_shutdown(None)
        return
    try:
        period = 1.0 / float(rate)
    except (TypeError, ValueError, ZeroDivisionError):
        raise ROSTopicException("Rate must be a number") from None
    next_time = time.monotonic()
    while not node.is_shutdown():
        if substitute_keywords:
            msg = _library(lambda: _fill(msg_class, pub_args))
        if verbose:
            print(f"publishing {msg}")
            flush_stdout()
        pub.publish(msg)
        next_time += period
        if node.wait_for_shutdown(max(next_time - time.monotonic(), 0.0)):
            break


def argv_publish(pub: Any, msg_class: Any, pub_args: Any, rate: float | None, once: bool,
                 verbose: bool, substitute_keywords: bool = False) -> None:
    """publish_message, then (with ``once``) stay 3 s so that subscribers get it."""
    from minros import node

    publish_message(pub, msg_class, pub_args, rate, once, verbose=verbose,
                    substitute_keywords=substitute_keywords)
    if once:
        node.wait_for_shutdown(ONCE_DELAY)


def wait_for_subscriber(pub: Any, timeout: float) -> None:
    """Wait up to ``timeout`` s for ``pub`` to have a subscriber."""
    from minros import node

    deadline = time.monotonic() + timeout
    while pub.get_num_connections() == 0 and time.monotonic() < deadline:
        if node.wait_for_shutdown(0.01):
            return


def file_yaml_arg(filename: str) -> Callable[[], Any]:
    """A function giving an iterator of ``[document]`` for each YAML document of
    ``filename`` (rostopic pub -f)."""
    if not os.path.isfile(filename):
        raise ROSTopicException(f"file does not exist: {filename}")

    def documents() -> Any:
        for doc in _library(lambda: _file_documents(filename)):
            yield [doc]

    return documents


def stdin_yaml_arg() -> Any:
    """The YAML documents read from stdin (separated by ``---``) until EOF or shutdown."""
    return _stdin_documents()


def stdin_publish(pub: Any, msg_class: Any, rate: float | None, once: bool,
                  filename: str | None, verbose: bool) -> None:
    """Publish the documents of ``filename`` (or stdin), one per 1/``rate`` s; a single
    document with a rate is published repeatedly."""
    from minros import node

    if filename:
        docs = list(file_yaml_arg(filename)())
        one = len(docs) == 1
        source: Any = iter(docs)
    else:
        one, source = False, stdin_yaml_arg()
    period = 1.0 / rate if rate else None
    wait_for_subscriber(pub, SUBSCRIBER_TIMEOUT)
    for pub_args in source:
        if node.is_shutdown():
            break
        if pub_args:
            if not isinstance(pub_args, list):
                pub_args = [pub_args]
            if one and rate is not None:
                print("Got one message and a rate, publishing repeatedly")
                publish_message(pub, msg_class, pub_args, rate=rate, once=once, verbose=verbose)
            else:
                publish_message(pub, msg_class, pub_args, None, bool(period) or once,
                                verbose=verbose)
        if period is not None and node.wait_for_shutdown(period):
            break
        if once:
            break


def param_publish_once(pub: Any, msg_class: Any, param_name: str, verbose: bool) -> None:
    """Publish the message the parameter ``param_name`` holds (a field dictionary)."""
    from minros.client import params

    if not params.has_param(param_name):
        raise ROSTopicException(f"parameter does not exist: {param_name}")
    argv_publish(pub, msg_class, params.get_param(param_name), None, True, verbose)


def param_publish(pub: Any, msg_class: Any, param_name: str, rate: float | None,
                  verbose: bool) -> None:
    """Publish the message the parameter ``param_name`` holds, again each time it changes
    (the node subscribes to the parameter), or every 1/``rate`` s with its latest value."""
    from minros import node
    from minros.client import params

    if not params.has_param(param_name):
        raise ROSTopicException(f"parameter does not exist: {param_name}")

    def current() -> Any:
        value = params.get_param_cached(param_name)
        if isinstance(value, dict):
            return [value]
        if not isinstance(value, list):
            raise ROSTopicException(f"Parameter [{param_name}] in not a valid type")
        return value

    last: Any = None
    while not node.is_shutdown():
        pub_args = current()
        if rate is not None or pub_args != last:
            publish_message(pub, msg_class, pub_args, None, True, verbose=verbose)
            last = pub_args
        if node.wait_for_shutdown(1.0 / rate if rate else 0.1):
            break


if __name__ == "__main__":  # rosrun rostopic rostopic / <node pkg="rostopic" type="rostopic">
    sys.exit(main(sys.argv[1:]))
