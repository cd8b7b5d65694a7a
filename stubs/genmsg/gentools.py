"""genmsg.gentools: md5 sums and full texts of specs (minros.msgs.loader)."""

from genmsg.base import InvalidMsgSpec  # noqa: E402, F401
from genmsg.msg_loader import load_depends  # noqa: E402, F401
from genmsg.msgs import MsgSpec, bare_msg_type, is_builtin  # noqa: E402, F401
from genmsg.srvs import SrvSpec  # noqa: E402, F401
from minros.msgs.loader import (  # noqa: F401
    compute_full_text,
    compute_full_type_name,
    compute_md5,
    compute_md5_text,
)
