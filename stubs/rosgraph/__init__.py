"""Stand-in for rosgraph: the master API, graph names, the network and environment rules
(minros.tools.master, minros.names, minros.rosenv)."""

from __future__ import annotations

import sys
from typing import List, Sequence

from minros.names import REMAP

from . import masterapi, names, network, rosenv  # noqa: F401
from .masterapi import Master, MasterError, MasterException, MasterFailure
from .masterapi import is_online as is_master_online
from .rosenv import ROS_HOSTNAME, ROS_IP, ROS_IPV6, ROS_MASTER_URI, ROS_NAMESPACE, get_master_uri

__all__ = ["myargv", "get_master_uri", "ROS_MASTER_URI", "ROS_NAMESPACE", "ROS_HOSTNAME",
           "ROS_IP", "ROS_IPV6", "Master", "MasterFailure", "MasterError", "MasterException",
           "is_master_online"]


def myargv(argv: Sequence[str] | None = None) -> List[str]:
    """``argv`` (default sys.argv) without the arguments holding ``:=``."""
    return [a for a in (sys.argv if argv is None else argv) if REMAP not in a]
