"""rostopic's Python API (the stand-in ``rostopic`` re-exports it): the same code as the
commands (:mod:`minros.cli.topic` and the modules it dispatches to), with rostopic's
exceptions instead of exit statuses."""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from typing import Any, Callable, Dict, List, Tuple

from minros import names
from minros.cli.topic import main
from minros.cli.topic_common import (
    NAME,
    ONCE_DELAY,
    SUBSCRIBER_TIMEOUT,
    checked_master,
    get_topic_list,
    info_text,
    master_client,
    message_class,
    ros_now,
    topic_type,
    wait_topic_type,
)
from minros.cli.topic_pub import file_documents, fill_message, stdin_documents
from minros.cli.topic_rates import HzStats, format_bw
from minros.tools.common import flush_stdout, resolve
from minros.tools.master import Master, MasterError


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
    return plot_line(val, ros_now(), time_offset, field_filter)


def get_topic_type(topic: str, blocking: bool = False) -> Tuple[str | None, str | None, Any]:
    """``(type, topic, field evaluator)`` of a topic or of a field of one (``/odom/pose``);
    ``(None, None, None)`` when nobody publishes it, unless ``blocking`` waits for it."""
    def run() -> Tuple[str | None, str | None, Any]:
        master = master_client()
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
    cls = message_class(type_name)
    if cls is None:
        raise ROSTopicException(f"Cannot load message class for [{type_name}]. "
                                "Are your messages built?")
    return cls, real, evaluator


def get_info_text(topic: str) -> str:
    """What ``rostopic info TOPIC`` prints."""
    return _library(lambda: info_text(master_client(), resolve(NAME, topic)))


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
        self._for(topic).tick(time.time() if self.use_wtime else ros_now().to_sec())

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
    _library(lambda: checked_master() and None)


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
        type_name, real, field = topic_type(master_client(), topic)
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
    return _library(lambda: get_topic_list(master if isinstance(master, Master) else master_client()))


def find_by_type(topic_type: str) -> List[str]:
    """The topics published with type ``topic_type`` (``rostopic find``)."""
    return _library(lambda: [t for t, ty in master_client().topic_types() if ty == topic_type])


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
                offset = ros_now() if self.offset_time else None
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
            return format_bw(list(self.sizes), list(self.times), time.time())

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
            now = ros_now()
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

    msg = _library(lambda: fill_message(msg_class, pub_args))
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
            msg = _library(lambda: fill_message(msg_class, pub_args))
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
        for doc in _library(lambda: file_documents(filename)):
            yield [doc]

    return documents


def stdin_yaml_arg() -> Any:
    """The YAML documents read from stdin (separated by ``---``) until EOF or shutdown."""
    return stdin_documents()


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
