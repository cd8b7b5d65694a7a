"""rosmaster.master_api: the Master and Parameter Server XML-RPC API (minros.master)."""

from __future__ import annotations

import logging

from minros.master import CallbackPool, MasterHandler
from minros.wire.rosapi import api as apivalidate  # noqa: F401 - rosmaster's decorator name

NUM_WORKERS = 3  # rosmaster's default number of threads calling nodes back
LOG_API = False
_logger = logging.getLogger("rosmaster.master")


def mloginfo(msg: str, *args: object) -> None:
    _logger.info(msg, *args)


def mlogwarn(msg: str, *args: object) -> None:
    _logger.warning(msg, *args)


class ROSMasterHandler(MasterHandler):
    """The master's XML-RPC handler, with ``num_workers`` threads calling nodes back."""

    def __init__(self, num_workers: int = NUM_WORKERS) -> None:
        super().__init__(CallbackPool(max(1, num_workers)))

    def _ok(self) -> bool:
        return not self._shutdown_requested.is_set()
