"""rospy.impl: rospy's internals, each over minros's node and client library
(minros.rospy_internals). Submodules load on first use (``rospy.impl.tcpros_base`` works after
a bare ``import rospy``, as in rospy), so ``import rospy`` does not pay for them."""

from __future__ import annotations

import importlib
from typing import Any

_SUBMODULES = ("init", "masterslave", "paramserver", "registration", "rosout", "simtime",
               "statistics", "tcpros", "tcpros_base", "tcpros_pubsub", "tcpros_service",
               "transport", "validators")


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'rospy.impl' has no attribute '{name}'")
