"""transform INPUT OUTPUT_TOPIC OUTPUT_TYPE [EXPRESSION] [--import MOD ...]: publish a Python
expression of each message ``m`` of INPUT (a topic, or a field of one: ``/imu/orientation``)
as OUTPUT_TYPE on OUTPUT_TOPIC; a list or tuple result is the output's constructor arguments."""

from __future__ import annotations

import argparse
import importlib
import sys
import time
from typing import Any, Callable, List, Optional, Tuple

import minros
from minros.msgs import get_message_class
from minros.nodes.topic_tools._common import program_args
from minros.tools.echo import make_field_getter

DESCRIPTION = """Apply a Python operation to a topic.

A node is created that subscribes to a topic,
applies a Python expression to the topic (or topic
field) message 'm', and publishes the result
through another topic.

Usage:
\trosrun topic_tools transform <input> <output topic> <output type> [<expression on m>] [--import numpy tf]

Example:
\trosrun topic_tools transform /imu/orientation /norm std_msgs/Float64 'sqrt(sum(array([m.x, m.y, m.z, m.w])))'"""


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="transform", description=DESCRIPTION,
                                formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("input", help="Input topic or topic field.")
    p.add_argument("output_topic", help="Output topic.")
    p.add_argument("output_type", help="Output topic type.")
    p.add_argument("expression", nargs="?", default="m",
                   help="Python expression to apply on the input message 'm'.")
    p.add_argument("-i", "--import", dest="modules", nargs="+", default=["numpy"],
                   help="List of Python modules to import.")
    p.add_argument("--wait-for-start", action="store_true", help="Wait for input messages.")
    p.add_argument("--latch", action="store_true", help="Set publisher to latched.")
    p.add_argument("--tcpnodelay", dest="tcp_nodelay", action="store_true",
                   help="Set TCP_NODELAY transport hint when subscribing to topics.")
    return p


def split_topic(name: str, published: List[Tuple[str, str]]) -> Tuple[Optional[str], str, str]:
    """(topic, type, field path) for a topic or topic field among ``published``."""
    types = dict(published)
    candidate = name.rstrip("/")
    while candidate:
        if candidate in types:
            return candidate, types[candidate], name[len(candidate):]
        candidate = candidate.rsplit("/", 1)[0]
    return None, "", ""


def main(argv: Optional[List[str]] = None) -> int:
    args = parser().parse_args(program_args(argv))
    modules = {}
    for module in args.modules:
        try:
            modules[module] = importlib.import_module(module)
        except ImportError:
            print(f"Failed to import module: {module}", file=sys.stderr)
    minros.init_node("transform", argv=list(sys.argv if argv is None else argv), anonymous=True)
    name = args.input if args.input.startswith("/") else minros.get_namespace() + args.input
    topic, type_name, field = split_topic(name, minros.get_published_topics())
    while topic is None and args.wait_for_start and not minros.is_shutdown():
        time.sleep(0.2)
        topic, type_name, field = split_topic(name, minros.get_published_topics())
    if topic is None:
        print(f"ERROR: Wrong input topic (or topic field): {name}", file=sys.stderr)
        return 1
    try:
        input_class = get_message_class(type_name)
        output_class = get_message_class(args.output_type)
    except Exception as exc:  # noqa: BLE001 - a type nobody installed: one line, then exit
        print(f"ERROR: {exc}", file=sys.stderr)
        return 1
    getter: Optional[Callable[[Any], Any]] = make_field_getter(field) if field else None
    pub = minros.Publisher(args.output_topic, output_class, queue_size=1, latch=args.latch)
    code = compile(args.expression, "<expression>", "eval")

    def callback(m: Any) -> None:
        if getter is not None:
            m = getter(m)
        try:
            result = eval(code, dict(modules), {"m": m})  # noqa: S307 - the user's expression
        except Exception as exc:  # noqa: BLE001 - report and keep serving
            print(f"Wrong expression {args.expression!r}: {type(exc).__name__}: {exc}",
                  file=sys.stderr)
            return
        if not isinstance(result, (list, tuple)):
            result = [result]
        pub.publish(*result)

    minros.Subscriber(topic, input_class, callback, tcp_nodelay=args.tcp_nodelay)
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
