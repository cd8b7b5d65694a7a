"""genpy.dynamic: message classes built at run time from a message_definition text."""

from __future__ import annotations

from minros.msgs import generate_dynamic

__all__ = ["generate_dynamic"]
