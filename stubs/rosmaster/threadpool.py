"""rosmaster.threadpool: a thread pool whose tasks with one marker never run at once
(minros.threadpool)."""

from minros.threadpool import MarkedThreadPool, ThreadPoolThread  # noqa: F401
