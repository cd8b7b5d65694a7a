"""DiagnosticStatusWrapper: a diagnostic_msgs/DiagnosticStatus with helpers to fill it."""

from __future__ import annotations

from typing import Any

from diagnostic_msgs.msg import DiagnosticStatus, KeyValue

OK = DiagnosticStatus.OK
WARN = DiagnosticStatus.WARN
ERROR = DiagnosticStatus.ERROR


class DiagnosticStatusWrapper(DiagnosticStatus):
    """A DiagnosticStatus message (publishable as one) with summary and key/value helpers."""

    def __init__(self, *args: Any, **kwds: Any) -> None:
        DiagnosticStatus.__init__(self, *args, **kwds)

    def summary(self, *args: Any) -> None:
        """``summary(status)`` copies level and message; ``summary(level, message)`` sets them."""
        if len(args) == 1:
            self.level = args[0].level
            self.message = args[0].message
        elif len(args) == 2:
            self.level = args[0]
            self.message = str(args[1])

    def clearSummary(self) -> None:
        self.summary(0, "")

    def mergeSummary(self, *args: Any) -> None:
        """Merge a level and message (or another status's) into this one: the higher level
        wins; messages of two non-OK levels (or two OK ones) are joined with "; "."""
        if len(args) == 1:
            level, message = args[0].level, args[0].message
        elif len(args) == 2:
            level, message = args[0], args[1]
        else:
            return
        if (level > 0) == (self.level > 0):
            if self.message:
                self.message += "; "
            self.message += message
        elif level > self.level:
            self.message = message
        if level > self.level:
            self.level = level

    def add(self, key: str, val: Any) -> None:
        """Append the key/value pair ``key: str(val)``."""
        self.values.append(KeyValue(key, str(val)))
