"""Signals handled outside the signal handler.

Python runs a handler in the main thread between two bytecodes: possibly while that thread holds
a lock (a connection's, in the middle of a publish), or while it is inside an earlier handler's
``Event.set()``. A handler that takes a lock can therefore deadlock the process; two Ctrl-C in a
row, or a ``killpg`` and a parent's own SIGINT arriving together, are enough. So a minros
handler only writes the signal's number to a pipe (no lock, async-signal-safe), and a thread of
its own reads the pipe and does the work.
"""

from __future__ import annotations

import os
import signal
import threading
from typing import Any, Callable, Dict, Iterable

__all__ = ["SignalWatch"]


class SignalWatch:
    """Calls ``callback(signum)`` from a daemon thread named ``name`` for every signal that
    :meth:`handler` saw."""

    def __init__(self, callback: Callable[[int], Any], name: str) -> None:
        self.callback = callback
        self._read, self._write = os.pipe()
        os.set_blocking(self._write, False)
        threading.Thread(target=self._run, name=name, daemon=True).start()

    def handler(self, signum: int, frame: Any = None) -> None:
        """The part that runs in the handler: one byte into the pipe."""
        try:
            os.write(self._write, bytes([signum & 0xFF]))
        except OSError:  # the pipe is full: the thread has plenty to do already
            pass

    def install(self, signums: Iterable[int]) -> Dict[int, Any]:
        """Make :meth:`handler` the handler of ``signums`` (main thread only); returns the
        handlers it replaced."""
        return {signum: signal.signal(signum, self.handler) for signum in signums}

    def _run(self) -> None:
        while True:
            for signum in os.read(self._read, 64):
                self.callback(signum)
