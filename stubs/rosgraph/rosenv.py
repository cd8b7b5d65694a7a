"""rosgraph.rosenv: the ROS environment variables and the master URI (minros.rosenv)."""

from __future__ import annotations

import sys
from typing import Mapping, Sequence

from minros import rosenv
from minros.rosenv import DEFAULT_MASTER_PORT, DEFAULT_MASTER_URI  # noqa: F401

ROS_MASTER_URI = "ROS_MASTER_URI"
ROS_IP = "ROS_IP"
ROS_IPV6 = "ROS_IPV6"
ROS_HOSTNAME = "ROS_HOSTNAME"
ROS_NAMESPACE = "ROS_NAMESPACE"


def get_master_uri(env: Mapping[str, str] | None = None, argv: Sequence[str] | None = None) -> str:
    """``__master:=`` in ``argv`` (default sys.argv), else ROS_MASTER_URI, else the default."""
    return rosenv.get_master_uri(env, rosenv.remapped_master(sys.argv if argv is None else argv))
