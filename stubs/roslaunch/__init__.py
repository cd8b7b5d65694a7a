"""Stand-in for roslaunch's Python API (minros.launch: the loader and runner of the command)."""

from __future__ import annotations

from typing import List

from minros.launch.api import RLException  # noqa: F401

from . import core, parent, rlutil, scriptapi  # noqa: F401


def configure_logging(uuid: str) -> None:
    """roslaunch sets up its own log file here; minros's launcher logs nodes per run id."""


def main(argv: List[str] | None = None) -> int:
    import sys

    from minros.cli.launch import main as launch_main

    return launch_main(list(sys.argv if argv is None else argv)[1:], prog="roslaunch")
