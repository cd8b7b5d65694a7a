"""dynamic_reconfigure.client: Client (minros.dynamic_reconfigure.client)."""

from minros.dynamic_reconfigure.client import Client  # noqa: F401
