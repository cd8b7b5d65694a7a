"""switch_mux MUXED_TOPIC SELECT_TOPIC: select a mux's input through its deprecated
``<MUXED_TOPIC>_select`` service (mux_select, which calls ``mux/select``, replaces it)."""

from __future__ import annotations

import sys
from typing import List, Optional

import minros
from minros.nodes.topic_tools._common import base_name, program_args, usage_error
from topic_tools.srv import MuxSelect

USAGE = "usage: switch MUXED_TOPIC SELECT_TOPIC"


def main(argv: Optional[List[str]] = None) -> int:
    args = program_args(argv)
    if args[:1] in (["-h"], ["--help"]):
        print(USAGE)
        return 0
    if len(args) < 2:
        return usage_error(USAGE)
    try:
        name = base_name(args[0]) + "_switcher"
    except ValueError as exc:
        return usage_error(USAGE, str(exc))
    print("topic_tools/switch_mux is deprecated; please use topic_tools/mux_select instead",
          file=sys.stderr)
    minros.init_node(name, argv=list(sys.argv if argv is None else argv))
    service = args[0] + "_select"
    minros.loginfo(f"Waiting for service {service}...")
    try:
        minros.wait_for_service(service)
        response = minros.ServiceProxy(service, MuxSelect)(args[1])
    except minros.ServiceException as exc:
        minros.logerr(f"failed to switch muxed topic {args[0]} to {args[1]}: {exc}")
        return 1
    except minros.ROSInterruptException:
        return 1
    minros.loginfo(f"muxed topic {args[0]} successfully switched from {response.prev_topic} "
                   f"to {args[1]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
