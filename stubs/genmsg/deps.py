"""genmsg.deps: the message files a .msg or .srv depends on (minros.msgs.loader)."""

from minros.msgs.loader import (  # noqa: F401
    find_msg_dependencies,
    find_msg_dependencies_with_type,
    find_srv_dependencies,
    find_srv_dependencies_with_type,
)
