"""genmsg.msgs: specs, fields, constants and type-name rules (minros.msgs.loader)."""

from genmsg.base import log  # noqa: E402, F401
from genmsg.names import resource_name  # noqa: E402, F401
from minros.msgs.loader import (  # noqa: F401
    BUILTIN_TYPES,
    DURATION,
    DURATION_MSG,
    HEADER,
    HEADER_FULL_NAME,
    PRIMITIVE_TYPES,
    TIME,
    TIME_MSG,
    Constant,
    Field,
    InvalidMsgSpec,
    MsgSpec,
    bare_msg_type,
    is_builtin,
    is_header_type,
    is_valid_constant_type,
    is_valid_msg_field_name,
    is_valid_msg_type,
    parse_type,
    resolve_type,
)
from minros.names import (  # noqa: F401
    is_legal_resource_base_name,
    is_legal_resource_name,
    package_resource_name,
)

EXT_MSG = ".msg"
MSG_DIR = "msg"
SEP = "/"
