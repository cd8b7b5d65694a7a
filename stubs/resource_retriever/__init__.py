"""resource_retriever stand-in (see minros.resource_retriever)."""

from minros.resource_retriever import *  # noqa: F401,F403
from minros.resource_retriever import __all__ as __all__  # noqa: PLC0414
