"""relay IN_TOPIC [OUT_TOPIC]: republish every message of IN_TOPIC on OUT_TOPIC
(IN_TOPIC_relay by default), whatever its type."""

from __future__ import annotations

import sys
from typing import List, Optional

import minros
from minros.nodes.topic_tools._common import base_name, init, program_args, usage_error
from minros.topic_tools.shapeshifter import RawOutput

USAGE = "\nusage: relay IN_TOPIC [OUT_TOPIC]\n"


def main(argv: Optional[List[str]] = None) -> int:
    args = program_args(argv)
    if len(args) in (1, 2) and args[0] in ("-h", "--help"):
        print(USAGE)
        return 0
    if len(args) not in (1, 2):
        return usage_error(USAGE)
    in_topic = args[0]
    out_topic = args[1] if len(args) == 2 else in_topic + "_relay"
    init(base_name(in_topic) + "_relay", argv)
    output = RawOutput(out_topic)
    minros.Subscriber(in_topic, minros.AnyMsg, output.forward,
                      tcp_nodelay=not minros.get_param("~unreliable", False))
    minros.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
