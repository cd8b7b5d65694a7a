"""The master's log: what it did (``+PUB``, ``-SUB``, ``+PARAM`` ... as in rosmaster's
master.log). No handler is attached unless :func:`configure_log_file` is called, so library
use stays silent."""

from __future__ import annotations

import logging
import os

from minros import logfiles

log = logging.getLogger("minros.master")
log.propagate = False


def configure_log_file(path: str) -> bool:
    """Write the master's log to ``path`` (rosmaster's master.log), rotated as rospy rotates
    it (50 MB, 4 old files) with lines truncated (a caller_id is the client's to choose);
    False if it cannot."""
    try:
        os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
        handler = logfiles.rotating_handler(path, "[%(name)s][%(levelname)s] %(asctime)s: %(message)s")
    except OSError:
        return False
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    return True
