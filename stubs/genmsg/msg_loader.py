"""genmsg.msg_loader: MsgContext and the loaders (minros.msgs.loader)."""

from genmsg.base import log  # noqa: E402, F401
from genmsg.msgs import MsgSpec, bare_msg_type, is_builtin, is_valid_constant_type, resolve_type  # noqa: E402, F401
from genmsg.names import normalize_package_context, package_resource_name  # noqa: E402, F401
from genmsg.srvs import SrvSpec  # noqa: E402, F401
from minros.msgs.loader import (  # noqa: F401
    Constant,
    Field,
    InvalidMsgSpec,
    MsgContext,
    MsgNotFound,
    _load_constant_line,
    _load_field_line,
    _strip_comments,
    convert_constant_value,
    get_msg_file,
    get_srv_file,
    is_valid_msg_field_name,
    is_valid_msg_type,
    load_depends,
    load_msg_by_type,
    load_msg_depends,
    load_msg_from_file,
    load_msg_from_string,
    load_srv_by_type,
    load_srv_from_file,
    load_srv_from_string,
)

COMMENTCHAR = "#"
CONSTCHAR = "="
DURATION = "duration"
EXT_MSG = ".msg"
EXT_SRV = ".srv"
HEADER = "Header"
HEADER_FULL_NAME = "std_msgs/Header"
IODELIM = "---"
SEP = "/"
TIME = "time"
