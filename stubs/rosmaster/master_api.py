"""rosmaster.master_api: the Master and Parameter Server XML-RPC API (minros.master.handler)."""

from __future__ import annotations

import logging

from minros.master.callbacks import CallbackPool
from minros.master.handler import MasterHandler
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

from rosgraph.names import resolve_name  # noqa: E402, F401
from rosgraph.xmlrpc import XmlRpcHandler  # noqa: E402, F401
from rosmaster.registrations import RegistrationManager  # noqa: E402, F401
from rosmaster.util import xmlrpcapi  # noqa: E402, F401
from rosmaster.validators import (  # noqa: E402, F401
    ParameterInvalid,
    empty_or_valid_name,
    is_api,
    is_service,
    is_topic,
    non_empty,
    non_empty_str,
    not_none,
    valid_name,
    valid_type_name,
)

MSG = 1
STATUS = 0
VAL = 2
