"""genmsg.msg_loader: MsgContext and the loaders (minros.msgs.loader)."""

from minros.msgs.loader import (  # noqa: F401
    InvalidMsgSpec,
    MsgContext,
    MsgNotFound,
    get_msg_file,
    get_srv_file,
    load_depends,
    load_msg_by_type,
    load_msg_depends,
    load_msg_from_file,
    load_msg_from_string,
    load_srv_by_type,
    load_srv_from_file,
    load_srv_from_string,
)
