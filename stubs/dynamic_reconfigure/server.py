"""dynamic_reconfigure.server: Server (minros.dynamic_reconfigure.server)."""

from minros.dynamic_reconfigure.server import Server  # noqa: F401
