"""What the topic_tools programs share: arguments, node names, the error exit."""

from __future__ import annotations

import sys
from typing import List, Optional

import minros


def program_args(argv: Optional[List[str]]) -> List[str]:
    """The program's own arguments (remappings and ``__name:=`` removed)."""
    return minros.myargv(list(sys.argv if argv is None else argv))[1:]


def base_name(topic: str) -> str:
    """The node name ROS's programs derive from a topic: its last part. ValueError for a name
    that has none (``//``), which ROS's programs refuse before they contact a master."""
    name = topic.rstrip("/").rsplit("/", 1)[-1]
    if not name:
        raise ValueError(f'Base name extracted from "{topic}" is an empty string: '
                         "give a topic name")
    return name


def usage_error(usage: str, problem: str = "") -> int:
    if problem:
        print(f"error: {problem}", file=sys.stderr)
    print(usage, file=sys.stderr)
    return 1


def init(default_name: str, argv: Optional[List[str]]) -> None:
    # anonymous, as ROS's programs: two relays of one topic can run side by side
    minros.init_node(default_name, argv=list(sys.argv if argv is None else argv), anonymous=True)
