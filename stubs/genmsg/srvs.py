"""genmsg.srvs: SrvSpec (minros.msgs.loader)."""

from minros.msgs.loader import SrvSpec  # noqa: F401
