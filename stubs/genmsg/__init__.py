"""Stand-in for genmsg: loading .msg/.srv specs, md5 sums and full texts (minros.msgs.loader
over minros's parser)."""

from minros.msgs.loader import (  # noqa: F401
    DURATION,
    EXT_MSG,
    EXT_SRV,
    HEADER,
    MSG_DIR,
    SEP,
    SRV_DIR,
    TIME,
    Constant,
    Field,
    InvalidMsgSpec,
    MsgContext,
    MsgGenerationException,
    MsgNotFound,
    MsgSpec,
    SrvSpec,
    compute_full_text,
    compute_md5,
    compute_md5_text,
    load_depends,
    load_msg_by_type,
    load_srv_by_type,
)
from minros.names import (  # noqa: F401
    is_legal_resource_base_name,
    is_legal_resource_name,
    package_resource_name,
    resource_name,
    resource_name_base,
    resource_name_package,
)

from . import base, gentools, msg_loader, msgs, names, srvs  # noqa: F401, E402


def log(*args: object) -> None:
    """genmsg's verbose log (silent unless log_verbose(True))."""
    base.log(*args)


plog = base.plog
log_verbose = base.log_verbose
