"""Preempting a state machine when the node shuts down."""

from __future__ import annotations

import time

import minros
from minros.smach import Container

__all__ = ["set_preempt_handler"]


def set_preempt_handler(sc: Container) -> None:
    """On node shutdown, preempt ``sc`` and wait (up to 10 s) for it to stop; use it on the
    top-level container."""

    def handler() -> None:
        sc.request_preempt()
        deadline = time.monotonic() + 10.0
        while getattr(sc, "is_running", lambda: False)() and time.monotonic() < deadline:
            minros.loginfo("Received shutdown request... sent preempt... waiting for state "
                           "machine to terminate.")
            time.sleep(0.1)

    minros.on_shutdown(handler)
