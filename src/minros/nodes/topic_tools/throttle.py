"""throttle messages IN_TOPIC MSGS_PER_SEC [OUT_TOPIC] | throttle bytes IN_TOPIC
BYTES_PER_SEC WINDOW [OUT_TOPIC]: forward IN_TOPIC at a bounded rate (IN_TOPIC_throttle by
default). ``~wall_clock`` (bool) measures with the wall clock instead of ROS time."""

from __future__ import annotations

import sys
import time
from typing import Any, List, Optional

import minros
from minros.nodes.topic_tools._common import base_name, init, program_args, usage_error
from minros.topic_tools.policies import ByteThrottle, MessageThrottle, parse_float
from minros.topic_tools.shapeshifter import RawOutput

USAGE = """
usage:
  throttle messages IN_TOPIC MSGS_PER_SEC [OUT_TOPIC]]
OR
  throttle bytes IN_TOPIC BYTES_PER_SEC WINDOW [OUT_TOPIC]]

  This program will drop messages from IN_TOPIC so that either: the
  average bytes per second on OUT_TOPIC, averaged over WINDOW
  seconds, remains below BYTES_PER_SEC, or: the minimum inter-message
  period is 1/MSGS_PER_SEC. The messages are output
  to OUT_TOPIC, or (if not supplied), to IN_TOPIC_throttle.
"""


def main(argv: Optional[List[str]] = None) -> int:
    args = program_args(argv)
    if args[:1] in (["-h"], ["--help"]):
        print(USAGE)
        return 0
    try:
        if len(args) in (3, 4) and args[0] == "messages":
            in_topic = args[1]
            policy: Any = MessageThrottle(parse_float(args[2], "MSGS_PER_SEC"))
            out_topic = args[3] if len(args) == 4 else None
        elif len(args) in (4, 5) and args[0] == "bytes":
            in_topic = args[1]
            policy = ByteThrottle(parse_float(args[2], "BYTES_PER_SEC"),
                                  parse_float(args[3], "WINDOW"))
            out_topic = args[4] if len(args) == 5 else None
        else:
            return usage_error(USAGE)
    except ValueError as exc:
        return usage_error(USAGE, str(exc))
    try:
        name = base_name(in_topic) + "_throttle"
    except ValueError as exc:
        return usage_error(USAGE, str(exc))
    init(name, argv)
    output = RawOutput(out_topic or in_topic + "_throttle")
    wall = bool(minros.get_param("~wall_clock", False))

    def on_message(msg: Any) -> None:
        now = time.time() if wall else minros.get_time()
        if isinstance(policy, MessageThrottle):
            passes = policy.accept(now)
        else:
            passes = policy.accept(now, len(msg._buff))
        if passes:
            output.forward(msg)

    minros.Subscriber(in_topic, minros.AnyMsg, on_message,
                      tcp_nodelay=not minros.get_param("~unreliable", False))
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
