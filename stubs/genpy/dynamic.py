"""genpy.dynamic: message classes built at run time from a message_definition text."""

from __future__ import annotations

from minros.msgs import generate_dynamic

__all__ = ["generate_dynamic"]

from genmsg.base import MsgGenerationException  # noqa: E402, F401
from genmsg.msg_loader import MsgContext  # noqa: E402, F401
from genpy.generator import msg_generator  # noqa: E402, F401
