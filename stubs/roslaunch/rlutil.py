"""roslaunch.rlutil: the run id and the files named on a command line (minros.launch.api,
minros.cli.launch)."""

from __future__ import annotations

from typing import List

from minros.launch.api import get_or_generate_uuid  # noqa: F401
from minros.launch.rostools import check_roslaunch  # noqa: F401


def resolve_launch_arguments(args: List[str]) -> List[str]:
    """``[pkg] file.launch... arg:=value...`` -> the launch files' paths."""
    from minros.cli.launch import resolve_launch_arguments as resolve

    return resolve(list(args))[0]


DEFAULT_MASTER_PORT = 11311
