"""genpy.rostime: Time and Duration with genpy semantics."""

from __future__ import annotations

from minros.msgs import Duration, Time, TVal

__all__ = ["Time", "Duration", "TVal"]
