"""drop IN_TOPIC X Y [OUT_TOPIC]: drop X out of every Y messages of IN_TOPIC and forward the
rest to OUT_TOPIC (IN_TOPIC_drop by default)."""

from __future__ import annotations

import sys
from typing import Any, List, Optional

import minros
from minros.nodes.topic_tools._common import base_name, init, program_args, usage_error
from minros.topic_tools.policies import Dropper, parse_int
from minros.topic_tools.shapeshifter import RawOutput

USAGE = """
usage: drop IN_TOPIC X Y [OUT_TOPIC]

 This program will drop X out of every Y messages from IN_TOPIC,
 forwarding the rest to OUT_TOPIC if given, else to a topic
 named IN_TOPIC_drop
"""


def main(argv: Optional[List[str]] = None) -> int:
    args = program_args(argv)
    if args[:1] in (["-h"], ["--help"]):
        print(USAGE)
        return 0
    if len(args) not in (3, 4):
        return usage_error(USAGE)
    try:
        dropper = Dropper(parse_int(args[1], "X"), parse_int(args[2], "Y"))
    except ValueError as exc:
        return usage_error(USAGE, str(exc))
    in_topic = args[0]
    try:
        name = base_name(in_topic) + "_drop"
    except ValueError as exc:
        return usage_error(USAGE, str(exc))
    init(name, argv)
    output = RawOutput(args[3] if len(args) == 4 else in_topic + "_drop")

    def on_message(msg: Any) -> None:
        if dropper.accept():
            output.forward(msg)

    minros.Subscriber(in_topic, minros.AnyMsg, on_message,
                      tcp_nodelay=not minros.get_param("~unreliable", False))
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
