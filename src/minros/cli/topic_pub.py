"""``rostopic pub``: a message from the command line's YAML arguments, a file (``-f``) or
stdin, published latched, once (``-1``) or at a rate (``-r``)."""

from __future__ import annotations

import os
import sys
import time
from typing import Any, List

import yaml

from minros.cli.topic_common import (
    NAME,
    ONCE_DELAY,
    SUBSCRIBER_TIMEOUT,
    checked_master,
    init_tool_node,
    ros_now,
)
from minros.tools.common import ToolError, flush_stdout, option_parser, resolve


def fill_message(msg_class: Any, pub_args: list) -> Any:
    from minros.exceptions import MessageException
    from minros.msgs.fill import fill_message_args, printable_message_args, substitution_keys

    msg = msg_class()
    try:
        fill_message_args(msg, pub_args, substitution_keys(ros_now()))
    except (MessageException, ValueError, TypeError) as exc:
        raise ToolError(" ".join(str(exc).split()) + f" (Args are: [{printable_message_args(msg)}])") from None
    try:
        msg.serialize_to_bytes()
    except MessageException as exc:
        raise ToolError("Unable to publish message. One of the fields has an incorrect type: "
                        + " ".join(str(exc).split())) from None
    return msg


def file_documents(path: str) -> List[Any]:
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


def stdin_documents() -> Any:
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


def pub_cmd(argv: List[str], prog: str) -> int:
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
    checked_master()
    latch = rate is None or args.latch
    msg: Any = None
    if pub_args or not msg_class.__slots__:
        msg = fill_message(msg_class, pub_args)  # reject bad values before registering anything
    elif not args.file and sys.stdin.isatty():
        p.error("Please specify message values")
    from minros import node
    from minros.client.topics import Publisher

    init_tool_node(disable_rosout=True)
    pub = Publisher(topic, msg_class, latch=latch, queue_size=100)
    if msg is not None:
        _publish_args(pub, msg_class, msg, pub_args, rate, args)
        return 0
    # documents from -f FILE or stdin
    if rate is None and not args.latch and not args.once:
        rate = 10.0
    docs = file_documents(args.file) if args.file else None
    deadline = time.time() + SUBSCRIBER_TIMEOUT
    while pub.get_num_connections() == 0 and time.time() < deadline:
        if node.wait_for_shutdown(0.01):
            return 0
    if docs is not None and len(docs) == 1 and rate is not None:
        print("Got one message and a rate, publishing repeatedly")
        doc = docs[0]
        _publish_args(pub, msg_class, fill_message(msg_class, doc if isinstance(doc, list) else [doc]),
                      doc if isinstance(doc, list) else [doc], rate, args)
        return 0
    period = 1.0 / rate if rate else None
    for doc in (docs if docs is not None else stdin_documents()):
        if node.is_shutdown():
            break
        if doc is None:
            continue
        doc_args = doc if isinstance(doc, list) else [doc]
        m = fill_message(msg_class, doc_args)
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
            msg = fill_message(msg_class, pub_args)
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
