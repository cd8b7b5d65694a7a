"""minros.signals: a handler that only wakes a thread, so the work may take locks the
interrupted main thread holds (the deadlock a Ctrl-C in the middle of a publish caused)."""

from __future__ import annotations

import os
import signal
import threading

from minros.signals import SignalWatch


def test_work_runs_outside_the_handler_even_when_the_main_thread_holds_its_lock():
    lock = threading.Lock()
    seen = []
    done = threading.Event()

    def work(signum: int) -> None:
        with lock:  # held by the main thread when the signal arrives
            seen.append(signum)
            if len(seen) == 2:
                done.set()

    previous = SignalWatch(work, "test-signals").install([signal.SIGUSR1])
    try:
        with lock:
            os.kill(os.getpid(), signal.SIGUSR1)  # the handler runs here, inside the lock
            os.kill(os.getpid(), signal.SIGUSR1)
            assert not done.is_set()  # the work waits for the lock, in its own thread
        assert done.wait(5)
        assert seen == [signal.SIGUSR1, signal.SIGUSR1]
    finally:
        signal.signal(signal.SIGUSR1, previous[signal.SIGUSR1])
