"""rospy.numpy_msg: message classes whose numeric arrays are numpy views (minros.msgs)."""

from __future__ import annotations

from typing import Any


def numpy_msg(msg_type: Any) -> Any:
    from minros.msgs import numpy_msg as _numpy_msg

    return _numpy_msg(msg_type)
