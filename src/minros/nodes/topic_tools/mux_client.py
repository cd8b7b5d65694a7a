"""mux_select, mux_add, mux_delete, mux_list: call a mux's services from the command line."""

from __future__ import annotations

from typing import List, Optional

import minros
from minros.nodes.topic_tools._common import program_args
from topic_tools.srv import MuxAdd, MuxDelete, MuxList, MuxSelect

_TOOLS = {
    "mux_select": ("MUX_NAME TOPIC", "select", MuxSelect, "Selecting"),
    "mux_add": ("MUX_NAME TOPIC", "add", MuxAdd, "Adding"),
    "mux_delete": ("MUX_NAME TOPIC", "delete", MuxDelete, "Deleting"),
    "mux_list": ("MUX_NAME", "list", MuxList, ""),
}


def run(tool: str, argv: Optional[List[str]] = None) -> int:
    usage, service, srv_type, verb = _TOOLS[tool]
    args = program_args(argv)
    wanted = 1 if tool == "mux_list" else 2
    if len(args) != wanted:
        print(f"USAGE: {tool} {usage}")
        return 1
    name = f"{args[0]}/{service}"
    print(f'Waiting for service "{name}"')
    try:
        minros.wait_for_service(name, timeout=None)
        proxy = minros.ServiceProxy(name, srv_type)
        if tool == "mux_list":
            response = proxy()
            print(f"{args[0]} inputs: {list(response.topics)}")
        else:
            print(f'{verb} "{args[1]}" at mux "{args[0]}"')
            response = proxy(args[1])
            if tool == "mux_select":
                print(f"previous topic: {response.prev_topic!r}")
    except minros.ServiceException as exc:
        print(f"Service call failed: {exc}")
        return 1
    except minros.ROSInterruptException:
        return 1
    return 0


def mux_select(argv: Optional[List[str]] = None) -> int:
    return run("mux_select", argv)


def mux_add(argv: Optional[List[str]] = None) -> int:
    return run("mux_add", argv)


def mux_delete(argv: Optional[List[str]] = None) -> int:
    return run("mux_delete", argv)


def mux_list(argv: Optional[List[str]] = None) -> int:
    return run("mux_list", argv)
