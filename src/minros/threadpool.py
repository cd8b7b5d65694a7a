"""A pool of worker threads whose tasks carry a marker: two tasks with the same marker never run
at once (rosmaster's MarkedThreadPool, where the marker is the peer a task talks to, so one
slow node cannot take every worker). Tasks without a marker (None) run as workers free up."""

from __future__ import annotations

import logging
import threading
from typing import Any, Callable, List, Optional, Set, Tuple

_logger = logging.getLogger("rosmaster.threadpool")

Task = Tuple[Any, Optional[Callable[..., Any]], Any, Optional[Callable[[Any], Any]]]


class MarkedThreadPool:
    """``queue_task(marker, task, args, taskCallback)``: ``task(*args)`` runs on a worker,
    then ``taskCallback(result)``; ``set_thread_count`` resizes, ``join_all`` ends the pool."""

    def __init__(self, numThreads: int) -> None:  # noqa: N803 - rosmaster's parameter name
        self._threads: List[ThreadPoolThread] = []
        self._resize_lock = threading.Lock()
        self._cond = threading.Condition()
        self._tasks: List[Task] = []
        self._markers: Set[Any] = set()
        self._joining = False
        self.set_thread_count(numThreads)

    def set_thread_count(self, newNumThreads: int) -> bool:  # noqa: N803
        """Grow or shrink the pool to ``newNumThreads`` workers; False while joining."""
        if self._joining:
            return False
        with self._resize_lock:
            self._resize(newNumThreads)
        return True

    def _resize(self, count: int) -> None:
        while count > len(self._threads):
            thread = ThreadPoolThread(self)
            self._threads.append(thread)
            thread.start()
        while count < len(self._threads):
            self._threads.pop(0).go_away()
        with self._cond:
            self._cond.notify_all()  # a retiring worker waiting for a task sees it must go

    def get_thread_count(self) -> int:
        with self._resize_lock:
            return len(self._threads)

    def queue_task(self, marker: Any, task: Callable[..., Any], args: Any = None,
                   taskCallback: Optional[Callable[[Any], Any]] = None) -> bool:  # noqa: N803
        """Queue ``task``; False (nothing queued) while joining or when it is not callable."""
        if self._joining or not callable(task):
            return False
        with self._cond:
            self._tasks.append((marker, task, args, taskCallback))
            self._cond.notify_all()
        return True

    def remove_marker(self, marker: Any) -> None:
        """The task holding ``marker`` is done: the next one with it may run."""
        if marker is None:
            return
        with self._cond:
            self._markers.discard(marker)
            self._cond.notify_all()

    def get_next_task(self) -> Task:
        """The first queued task whose marker is free (marked busy now), or four Nones."""
        with self._cond:
            return self._take()

    def _take(self) -> Task:
        for item in self._tasks:
            marker = item[0]
            if marker is None or marker not in self._markers:
                self._tasks.remove(item)
                if marker is not None:
                    self._markers.add(marker)
                return item
        return (None, None, None, None)

    def _wait_for_task(self, worker: ThreadPoolThread, timeout: float) -> Task:
        with self._cond:
            item = self._take()
            if item[1] is None and not worker.is_dying():
                self._cond.wait(timeout)
                item = self._take()
            return item

    def _idle(self) -> bool:
        with self._cond:
            return not self._tasks

    def join_all(self, wait_for_tasks: bool = True, wait_for_threads: bool = True) -> None:
        """Stop taking tasks, let the queue drain (``wait_for_tasks``), end every worker and
        wait for them (``wait_for_threads``)."""
        self._joining = True
        if wait_for_tasks:
            with self._cond:
                while self._tasks:
                    self._cond.wait(0.1)
        with self._resize_lock:
            threads = list(self._threads)
            self._resize(0)
            if wait_for_threads:
                for thread in threads:
                    thread.join()
            self._joining = False


class ThreadPoolThread(threading.Thread):
    """One worker of a :class:`MarkedThreadPool`."""

    threadSleepTime = 0.1  # seconds a worker waits for a task before checking it must go

    def __init__(self, pool: MarkedThreadPool) -> None:
        super().__init__(daemon=True, name="MarkedThreadPool worker")
        self._pool = pool
        self._dying = threading.Event()

    def run(self) -> None:
        pool = self._pool
        while not self._dying.is_set():
            marker, task, args, callback = pool._wait_for_task(self, self.threadSleepTime)
            if task is None:
                continue
            try:
                result = task(*args) if args is not None else task()
                if callback is not None:
                    callback(result)
            except Exception:  # a failing task must not end the worker
                _logger.exception("task of marker %r failed", marker)
            finally:
                pool.remove_marker(marker)

    def is_dying(self) -> bool:
        return self._dying.is_set()

    def go_away(self) -> None:
        """End after the current task."""
        self._dying.set()
