"""rosgraph.masterapi: Master and its errors (minros.tools.master)."""

from minros.rosenv import parse_http_host_and_port  # noqa: F401
from minros.tools.master import (  # noqa: F401
    Error,
    Failure,
    Master,
    MasterError,
    MasterException,
    MasterFailure,
    ROSMasterException,
    is_online,
)
from rosgraph.names import make_caller_id  # noqa: E402, F401
from rosgraph.rosenv import get_master_uri  # noqa: E402, F401
