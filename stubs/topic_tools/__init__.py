"""topic_tools stand-in: LazyTransport (minros.topic_tools) and the srv package."""

from minros.topic_tools import LazyTransport  # noqa: F401

__all__ = ("LazyTransport",)
