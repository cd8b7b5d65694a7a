#!/usr/bin/env python3
"""System calls per round trip and per persistent service call: minros, rospy, raw sockets.

    .venv/bin/python benchmarks/syscalls.py [--calls 2000] [--only minros,rospy,raw]

Each exchange of ``benchmarks/pubsub.py`` (the ping-pong round trip of a 20-byte
std_msgs/String, a persistent std_srvs/SetBool call) is run twice under ``strace -f -c``,
with few and with many calls; the difference of the two counts divided by the difference of
the calls is what one call costs, the start-up and the set-up cancelling out. Counts, not
times: they do not depend on how loaded the machine is. The raw floors are pubsub.py's: "raw"
for a round trip (two connections, a receive thread answering), "raw-1" for a service call
(one connection, blocking send then recv).

``futex`` counts the waits and wake-ups of threads that a system call shows: a contended
lock, a condition waited on, the GIL handed to another thread. Uncontended locks cost no
system call at all (see docs/internals.md, "What one call costs").
"""

from __future__ import annotations

import argparse
import collections
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from types import SimpleNamespace

import pubsub  # benchmarks/ is the script's directory: on sys.path
from _bytecode import byte_compile_minros

#: run a worker with every threading lock counting its acquisitions (written to argv[1] at
#: exit, and every 50 ms in case the process is killed)
_COUNT_LOCKS = r"""
import _thread, atexit, os, runpy, sys, threading, time
count = [0]
out = sys.argv.pop(1)
allocate, make_rlock = _thread.allocate_lock, threading._CRLock or threading._PyRLock

class Lock:
    __slots__ = ("_l",)
    def __init__(self):
        self._l = allocate()
    def acquire(self, blocking=True, timeout=-1):
        count[0] += 1
        return self._l.acquire(blocking, timeout)
    __enter__ = acquire
    def release(self):
        self._l.release()
    def __exit__(self, *exc):
        self._l.release()
    def locked(self):
        return self._l.locked()
    def _at_fork_reinit(self):
        self._l._at_fork_reinit()

class RLock(Lock):
    __slots__ = ()
    def __init__(self, *args, **kwargs):
        self._l = make_rlock()
    def _is_owned(self):
        return self._l._is_owned()
    def _release_save(self):
        return self._l._release_save()
    def _acquire_restore(self, state):
        count[0] += 1
        self._l._acquire_restore(state)

def dump():
    with open(out, "w") as f:
        f.write(str(count[0]))

def dumping():
    while True:
        time.sleep(0.05)
        dump()

threading.Lock = Lock
threading.RLock = RLock
atexit.register(dump)
threading.Thread(target=dumping, daemon=True).start()
sys.argv = sys.argv[1:]
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # as when run as a script
runpy.run_path(sys.argv[0], run_name="__main__")
"""


def _parse(path: str) -> collections.Counter:
    counts: collections.Counter = collections.Counter()
    with open(path) as f:
        for line in f:
            cols = line.split()
            if len(cols) >= 5 and cols[0][0].isdigit() and cols[-1] != "total":
                counts[cols[-1]] = int(cols[3])
    return counts


def _traced(command: tuple, out: str, locks: bool) -> tuple:
    if locks:
        python, *rest = command[0]
        return ([python, "-c", _COUNT_LOCKS, out, *rest], command[1])
    return (["strace", "-f", "-qq", "-c", "-o", out, *command[0]], command[1])


def _read_locks(path: str) -> collections.Counter:
    try:
        with open(path) as f:
            return collections.Counter({"locks": int(f.read() or 0)})
    except OSError:  # a process that takes no lock before it is stopped
        return collections.Counter({"locks": 0})


def _stop_tracee(strace: subprocess.Popen) -> None:
    """End what strace runs (strace then writes its summary and exits)."""
    try:
        with open(f"/proc/{strace.pid}/task/{strace.pid}/children") as f:
            children = [int(p) for p in f.read().split()]
    except OSError:
        children = []
    for pid in children:
        try:
            os.kill(pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
    try:
        strace.wait(10)
    except subprocess.TimeoutExpired:
        for pid in children:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        strace.wait(10)


def _run(runner: pubsub.Runner, who: str, exchange: str, calls: int, work: str,
         locks: bool = False) -> tuple:
    """(server side's counts, client side's counts) for ``calls`` calls."""
    port = str(pubsub._free_port())
    if exchange == "topic":
        if who == "raw":
            first = runner.command(who, "raw-pubsub-echo", ["--port", port])
            second = runner.command(who, "raw-pubsub-ping", ["--port", port, "--count", str(calls)])
        else:
            first = runner.command(who, "echo", ["--queue", "10"])
            second = runner.command(who, "ping", ["--queue", "10", "--count", str(calls)])
    else:
        if who == "raw":
            first = runner.command(who, "raw-echo", ["--port", port])
            second = runner.command(who, "raw-ping", ["--port", port, "--count", str(calls)])
        else:
            first = runner.command(who, "srv-server", [])
            second = runner.command(who, "srv-client", ["--persistent", "--count", str(calls)])
    out1, out2 = os.path.join(work, "server.txt"), os.path.join(work, "client.txt")
    for path in (out1, out2):
        if os.path.exists(path):
            os.remove(path)
    first, second = _traced(first, out1, locks), _traced(second, out2, locks)
    p1 = subprocess.Popen(first[0], env=first[1], stdout=subprocess.PIPE,
                          stderr=subprocess.DEVNULL, text=True)
    try:
        if "ready" not in p1.stdout.readline():
            raise RuntimeError(f"{who}: the {exchange} server did not start")
        p2 = subprocess.run(second[0], env=second[1], capture_output=True, text=True, timeout=300)
        if '"median_us"' not in p2.stdout:
            raise RuntimeError(f"{who}: the {exchange} client failed: {p2.stdout[-300:]}")
    finally:
        if locks:
            p1.send_signal(signal.SIGINT)  # a node shuts down: its counts are written at exit
            try:
                p1.wait(10)
            except subprocess.TimeoutExpired:
                p1.kill()
                p1.wait()
        else:
            _stop_tracee(p1)
    if locks:
        return _read_locks(out1), _read_locks(out2)
    return _parse(out1), _parse(out2)


def _per_call(low: collections.Counter, high: collections.Counter, calls: int) -> dict:
    return {name: (high[name] - low.get(name, 0)) / calls for name in high}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--calls", type=int, default=2000,
                        help="calls of the long run (the short run makes a quarter of them)")
    parser.add_argument("--only", default="minros,rospy,raw", help="comma-separated contenders")
    parser.add_argument("--exchanges", default="topic,service", help="topic, service or both")
    parser.add_argument("--baseline", default="", metavar="PY",
                        help="add 'baseline': minros run by this interpreter (another "
                             "checkout's venv), as in pubsub.py")
    parser.add_argument("--locks", action="store_true",
                        help="count the acquisitions of Python's threading locks instead "
                             "(no strace: every Lock and RLock counts what takes it)")
    args = parser.parse_args(argv)
    if not args.locks and not shutil.which("strace"):
        print("strace is not installed (apt-get install strace)", file=sys.stderr)
        return 1
    byte_compile_minros()
    runner = pubsub.Runner(SimpleNamespace(trace=False, baseline=args.baseline, only="",
                                           count=args.calls,
                                           minros_python=pubsub.VENV_PYTHON, seconds=2.0))
    work = tempfile.mkdtemp(prefix="minros-syscalls-")
    contenders = [c for c in args.only.split(",") if c != "rospy" or runner.reference]
    if args.baseline and "baseline" not in contenders:
        contenders.insert(1, "baseline")
    low_calls = max(args.calls // 4, 1)
    rows = []
    try:
        for exchange in args.exchanges.split(","):
            for who in contenders:
                t = time.monotonic()
                low = _run(runner, who, exchange, low_calls, work, args.locks)
                high = _run(runner, who, exchange, args.calls, work, args.locks)
                sides = [_per_call(low[i], high[i], args.calls - low_calls) for i in (0, 1)]
                rows.append((exchange, who, sides))
                print(f"{exchange} {who}: {time.monotonic() - t:.0f} s", file=sys.stderr, flush=True)
    finally:
        runner.close()
        shutil.rmtree(work, ignore_errors=True)
    side_names = {"topic": ("echo", "ping"), "service": ("server", "client")}
    what = "threading lock acquisitions" if args.locks else "system calls (strace -f -c)"
    print(f"{what} per call ({args.calls} - {low_calls} calls); {pubsub.machine()}")
    print("| exchange | contender | side | total | calls |")
    print("|---|---|---|---|---|")
    for exchange, who, sides in rows:
        for name, counts in zip(side_names[exchange], sides):
            shown = {k: v for k, v in counts.items() if v >= 0.05}
            text = ", ".join(f"{k} {v:.2f}".rstrip("0").rstrip(".")
                             for k, v in sorted(shown.items(), key=lambda kv: -kv[1]))
            print(f"| {exchange} | {who} | {name} | {sum(shown.values()):.1f} | {text} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
