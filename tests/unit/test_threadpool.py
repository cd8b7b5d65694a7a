"""rosmaster.threadpool: tasks run on the pool's workers, two tasks with one marker never at
once, callbacks get the results, join_all drains the queue and ends the workers."""

from __future__ import annotations

import threading

from rosmaster.threadpool import MarkedThreadPool


def test_tasks_run_and_callbacks_get_results():
    pool = MarkedThreadPool(3)
    results = []
    done = threading.Event()

    def collect(value):
        results.append(value)
        if len(results) == 10:
            done.set()

    for i in range(10):
        assert pool.queue_task(None, lambda x: x * x, (i,), collect)
    assert done.wait(5)
    assert sorted(results) == [i * i for i in range(10)]
    assert not pool.queue_task(None, "not callable")
    pool.join_all()
    assert pool.get_thread_count() == 0
    assert not any(t.name == "MarkedThreadPool worker" and t.is_alive() for t in threading.enumerate())


def test_one_marker_runs_one_task_at_a_time():
    pool = MarkedThreadPool(4)
    lock = threading.Lock()
    running = {"slow": 0, "max": 0, "other": 0}
    release = threading.Event()
    other_ran = threading.Event()

    def slow():
        with lock:
            running["slow"] += 1
            running["max"] = max(running["max"], running["slow"])
        release.wait(5)
        with lock:
            running["slow"] -= 1

    for _ in range(3):
        pool.queue_task("http://slow-node/", slow)
    pool.queue_task("http://other-node/", other_ran.set)
    # the other peer's task is not held up behind the slow peer's
    assert other_ran.wait(5)
    release.set()
    pool.join_all()
    assert running["max"] == 1 and running["slow"] == 0


def test_a_failing_task_does_not_end_its_worker():
    pool = MarkedThreadPool(1)
    ok = threading.Event()
    pool.queue_task("m", lambda: 1 / 0)
    pool.queue_task("m", ok.set)
    assert ok.wait(5)
    assert pool.set_thread_count(2) and pool.get_thread_count() == 2
    pool.join_all()
