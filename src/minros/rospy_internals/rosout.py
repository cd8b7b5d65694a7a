"""rospy.impl.rosout: logging to /rosout (minros.client.rosout_log)."""

from __future__ import annotations

import logging

from minros import node as _node
from minros.client import rosout_log
from minros.client.rosout_log import RosoutHandler as RosOutHandler  # noqa: F401


def init_rosout() -> bool:
    """Publish this node's log records on /rosout (init_node does it unless disabled)."""
    rosout_log.start_node_logging(_node.get_caller_id(), None, False)
    return True


def load_rosout_handlers(level: int) -> None:
    """Log records at ``level`` and above go to /rosout."""
    logger = logging.getLogger("rosout")
    if logger.level == logging.NOTSET or logger.level > level:
        logger.setLevel(level)
