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

from roslaunch.config import ROSLaunchConfig  # noqa: E402, F401
from roslaunch.core import Master, Node, Test  # noqa: E402, F401
from roslaunch.launch import ROSLaunchRunner  # noqa: E402, F401
from roslaunch.pmon import Process  # noqa: E402, F401
from roslaunch.scriptapi import ROSLaunch  # noqa: E402, F401
from roslaunch.xmlloader import XmlLoader, XmlParseException  # noqa: E402, F401

DEFAULT_MASTER_PORT = 11311
DEFAULT_TIMEOUT_SIGINT = 15.0
DEFAULT_TIMEOUT_SIGTERM = 2.0
NAME = "roslaunch"
NUM_WORKERS = 3
