"""rospy.impl.masterslave: the node's slave XML-RPC API (minros.node's SlaveApi) and the
argument checks it shares with the master (minros.wire.rosapi)."""

from __future__ import annotations

from typing import Any, Callable

from minros.node import SlaveApi as ROSHandler  # noqa: F401
from minros.wire.rosapi import ParameterInvalid
from minros.wire.rosapi import api as apivalidate  # noqa: F401

STATUS, MSG, VAL = 0, 1, 2  # the triplet's positions
#: rospy logs each slave API call at debug level (minros's slave API logs its own)
LOG_API = True


def is_publishers_list(param_name: str) -> Callable[[Any, str], Any]:
    """Validator: a list of XML-RPC URIs (publisherUpdate's argument)."""
    def check(value: Any, caller_id: str) -> Any:
        if not isinstance(value, list):
            raise ParameterInvalid(f"ERROR: param [{param_name}] must be a list")
        for item in value:
            if not isinstance(item, str):
                raise ParameterInvalid(f"ERROR: param [{param_name}] must be a list of strings")
            if not item.startswith("http://"):
                raise ParameterInvalid(f"ERROR: param [{param_name}] does not contain valid URLs [{item}]")
        return value
    return check
