"""Master benchmark: minros's master beside Debian's rosmaster (and roscore beside ``minros core``).

Run: ``.venv/bin/python benchmarks/master.py [--quick] [--only-load] [--baseline PY]``. Every
measurement uses the same client (Python's stdlib xmlrpc.client over one kept-alive connection
per thread) against each master, started fresh on a free loopback port, and prints one table.
"ratio" = Debian time / minros time (> 1 means minros is faster). ``--baseline PY`` adds the
master of another checkout (its venv's interpreter), measured in turn with the others, and
"base/minros" = its time / minros's (> 1 means this checkout is faster).

A second table is the load under attack of issue 18: 500 honest clients (threads in 4 client
processes, each call on a kept-alive connection) while 100 hostile ones trickle their headers
or announce 64 MiB bodies they never send: the honest clients' calls/s and p99; then the answer
time of getSystemState on a fresh connection during each attack of the issue, and the bytes
master.log takes for setParam calls with a 1 MiB caller_id.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import xmlrpc.client
from typing import Callable, Dict, List, Tuple

from _bytecode import byte_compile_minros  # benchmarks/ is the script's directory: on sys.path

PY = sys.executable


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def ros_env(port: int, home: str, reference: bool) -> Dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_") and k != "PYTHONPATH"}
    env.update(ROS_MASTER_URI=f"http://localhost:{port}", ROS_HOSTNAME="localhost", ROS_HOME=home,
               ROS_LOG_DIR=os.path.join(home, "log"))
    if reference:
        env.pop("VIRTUAL_ENV", None)
        env["PATH"] = "/usr/bin:/bin:/usr/sbin:/sbin"
    return env


MASTERS: Dict[str, Tuple[List[str], bool]] = {
    "minros master": ([PY, "-m", "minros.master", "-p", "{port}"], False),
    "Debian rosmaster": (["/usr/bin/rosmaster", "--core", "-p", "{port}"], True),
    "minros core": ([PY, "-m", "minros", "core", "-p", "{port}"], False),
    "Debian roscore": (["/usr/bin/roscore", "-p", "{port}"], True),
}


class Running:
    def __init__(self, kind: str, home: str) -> None:
        argv, reference = MASTERS[kind]
        self.port = free_port()
        self.proc = subprocess.Popen([a.format(port=self.port) for a in argv],
                                     env=ros_env(self.port, home, reference),
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                     stdin=subprocess.DEVNULL, start_new_session=True)
        self.started = time.perf_counter()
        self.first_answer = self._wait()

    def _wait(self, timeout: float = 30.0) -> float:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{self.port}/")
                if proxy.getPid("/bench")[0] == 1:
                    return time.perf_counter() - self.started
            except OSError:
                time.sleep(0.002)
        raise RuntimeError("master did not answer")

    def proxy(self) -> xmlrpc.client.ServerProxy:
        return xmlrpc.client.ServerProxy(f"http://127.0.0.1:{self.port}/")

    def stop(self) -> None:
        for sig, wait in ((signal.SIGINT, 3), (signal.SIGTERM, 2), (signal.SIGKILL, 2)):
            try:
                os.killpg(self.proc.pid, sig)
                self.proc.wait(wait)
                break
            except subprocess.TimeoutExpired:
                continue
            except ProcessLookupError:
                break


def timed(fn: Callable[[], object]) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def register_publishers(m: Running, count: int, prefix: str) -> float:
    proxy = m.proxy()

    def run() -> None:
        for i in range(count):
            code = proxy.registerPublisher(f"/bench_{prefix}_{i % 50}", f"/{prefix}/t{i}",
                                           "std_msgs/String", f"http://127.0.0.1:{40000 + i % 50}/")[0]
            assert code == 1
    return timed(run)


def system_state(m: Running, repeat: int) -> float:
    proxy = m.proxy()
    topics = len(proxy.getSystemState("/b")[2][0])
    assert topics >= 2000, topics
    return timed(lambda: [proxy.getSystemState("/b") for _ in range(repeat)]) / repeat


def concurrent_clients(m: Running, clients: int, calls: int) -> float:
    m.proxy().setParam("/b", "/bench/value", 42)
    barrier = threading.Barrier(clients + 1)
    errors: List[BaseException] = []

    def client() -> None:
        proxy = m.proxy()
        try:
            barrier.wait()
            for _ in range(calls):
                assert proxy.getParam("/b", "/bench/value")[2] == 42
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=client) for _ in range(clients)]
    for t in threads:
        t.start()
    barrier.wait()
    start = time.perf_counter()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
    return time.perf_counter() - start


def one_call_latency(m: Running, repeat: int) -> float:
    proxy = m.proxy()
    proxy.getPid("/b")
    return timed(lambda: [proxy.getPid("/b") for _ in range(repeat)]) / repeat


# ------------------------------------------------------------------ load under attack (issue 18)

HUGE_BODY = b"POST / HTTP/1.1\r\nContent-Type: text/xml\r\nContent-Length: 67108864\r\n\r\n<?xml"
SLOW_HEAD = b"POST / HTTP/1.1\r\nUser-Agent: " + b"slow" * 4096


class Hostile:
    """``count`` connections to ``port`` sending ``first``, then one more byte of ``trickle``
    each every ``interval`` seconds, until closed."""

    def __init__(self, port: int, count: int, first: bytes, trickle: bytes, interval: float) -> None:
        self.conns: List[socket.socket] = []
        for _ in range(count):
            s = socket.create_connection(("127.0.0.1", port), timeout=10)
            s.setblocking(False)
            try:
                s.send(first)
            except OSError:
                pass
            self.conns.append(s)
        self.trickle = trickle
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, args=(interval,), daemon=True)
        self.thread.start()

    def _run(self, interval: float) -> None:
        pos = 0
        while not self.stop.wait(interval):
            byte = self.trickle[pos % len(self.trickle):][:1]
            pos += 1
            for s in self.conns:
                try:
                    s.send(byte)
                except OSError:
                    pass

    def close(self) -> None:
        self.stop.set()
        self.thread.join(5)
        for s in self.conns:
            s.close()


def probe_times(port: int, count: int, timeout: float = 5.0) -> Tuple[List[float], int]:
    """getSystemState on a fresh connection ``count`` times: (answer times, unanswered)."""
    body = xmlrpc.client.dumps(("/probe",), "getSystemState").encode()
    request = b"POST / HTTP/1.1\r\nContent-Length: %d\r\n\r\n%s" % (len(body), body)
    times, missed = [], 0
    for _ in range(count):
        start = time.perf_counter()
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
                s.sendall(request)
                reply = b""
                while b"</methodResponse>" not in reply:
                    chunk = s.recv(65536)
                    if not chunk:
                        raise OSError("closed")
                    reply += chunk
            times.append(time.perf_counter() - start)
        except OSError:
            missed += 1
    return times, missed


def _honest_worker(port: int, threads: int, calls: int, queue: multiprocessing.Queue) -> None:
    barrier = threading.Barrier(threads)
    latencies: List[float] = []
    spans: List[Tuple[float, float]] = []
    errors: List[str] = []
    lock = threading.Lock()

    def client() -> None:
        proxy = xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/")
        mine = []
        try:
            proxy.getPid("/honest")  # connect before the clock starts
            barrier.wait()
            start = time.time()
            for _ in range(calls):
                t = time.perf_counter()
                proxy.getParam("/honest", "/bench/value")
                mine.append(time.perf_counter() - t)
            end = time.time()
        except Exception as exc:  # noqa: BLE001 - reported
            with lock:
                errors.append(repr(exc))
            return
        with lock:
            latencies.extend(mine)
            spans.append((start, end))

    workers = [threading.Thread(target=client) for _ in range(threads)]
    for t in workers:
        t.start()
    for t in workers:
        t.join()
    queue.put((latencies, spans, errors))


def honest_load(port: int, clients: int, calls: int, processes: int = 4) -> Tuple[float, float, int]:
    """(calls/s, p99 in ms, failed clients) of ``clients`` honest clients doing ``calls`` each."""
    xmlrpc.client.ServerProxy(f"http://127.0.0.1:{port}/").setParam("/b", "/bench/value", 42)
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    procs = [ctx.Process(target=_honest_worker, args=(port, clients // processes, calls, queue))
             for _ in range(processes)]
    for proc in procs:
        proc.start()
    results = [queue.get(timeout=600) for _ in procs]
    for proc in procs:
        proc.join()
    latencies = sorted(x for r in results for x in r[0])
    spans = [span for r in results for span in r[1]]
    failed = sum(len(r[2]) for r in results)
    if not spans:
        return 0.0, float("nan"), failed
    wall = max(e for _, e in spans) - min(s for s, _ in spans)
    p99 = latencies[int(len(latencies) * 0.99) - 1] * 1e3
    return len(latencies) / wall, p99, failed


def log_bytes(kind: str, calls: int) -> float:
    """MB of master.log (rotated files included) after ``calls`` setParam with a 1 MiB caller_id."""
    with tempfile.TemporaryDirectory() as home:
        os.makedirs(os.path.join(home, "log"))
        m = Running(kind, home)
        try:
            proxy = m.proxy()
            caller = "/" + "x" * (1 << 20)
            for i in range(calls):
                proxy.setParam(caller, f"/p{i}", i)
            proxy.getPid("/b")
            time.sleep(0.5)  # the log handler has written the last line
        finally:
            m.stop()
        log_dir = os.path.join(home, "log")
        return sum(os.path.getsize(os.path.join(log_dir, f)) for f in os.listdir(log_dir)
                   if f.startswith("master.log")) / 1e6


def load_section(quick: bool) -> None:
    kinds = ("minros master", "Debian rosmaster")
    calls = 10 if quick else 40
    probes = 10 if quick else 30
    reps = 1 if quick else 3
    log_calls = 60 if quick else 300
    samples: Dict[str, Dict[str, list]] = {kind: {} for kind in kinds}

    def add(kind: str, key: str, value: object) -> None:
        samples[kind].setdefault(key, []).append(value)

    with tempfile.TemporaryDirectory() as home:
        os.makedirs(os.path.join(home, "log"))
        for _rep in range(reps):
            # both masters run side by side, fresh each repetition, measured in turn
            running = {kind: Running(kind, home) for kind in kinds}
            try:
                for kind, m in running.items():
                    rate, p99, _failed = honest_load(m.port, 500, calls)
                    add(kind, "free_rate", rate)
                    add(kind, "free_p99", p99)
                for kind, m in running.items():
                    hostile = [Hostile(m.port, 50, SLOW_HEAD[:20], SLOW_HEAD[20:], 0.2),
                               Hostile(m.port, 50, HUGE_BODY, b"<", 1.0)]
                    try:
                        rate, p99, failed = honest_load(m.port, 500, calls)
                    finally:
                        for h in hostile:
                            h.close()
                    add(kind, "rate", rate)
                    add(kind, "p99", p99)
                    add(kind, "failed", failed)
                for label, count, first, rest, interval in (
                        ("bodies", 4, HUGE_BODY, b"<", 1.0),
                        ("heads", 1100, SLOW_HEAD[:1], SLOW_HEAD[1:], 0.2)):
                    for kind, m in running.items():
                        attack = Hostile(m.port, count, first, rest, interval)
                        try:
                            time.sleep(1.0)  # every hostile connection is in
                            times, missed = probe_times(m.port, probes)
                        finally:
                            attack.close()
                        samples[kind].setdefault(label, []).extend(times)
                        add(kind, label + "_missed", missed)
            finally:
                for m in running.values():
                    m.stop()
    for kind in kinds:
        add(kind, "log", log_bytes(kind, log_calls))

    def cell(kind: str, key: str) -> str:
        values = samples[kind].get(key, [])
        if key in ("bodies", "heads"):
            asked = probes * reps
            answered = f"{len(values)}/{asked}"
            return f"{statistics.median(values) * 1e3:.2f} ({answered})" if values else f"none ({answered})"
        text = f"{statistics.median(values):.1f}" if key != "free_rate" and key != "rate" \
            else f"{statistics.median(values):.0f}"
        if key == "rate" and sum(samples[kind]["failed"]):
            text += f" ({sum(samples[kind]['failed'])} failed)"
        return text

    rows = [
        ("500 honest clients alone: calls/s", "free_rate"),
        ("  p99 of one call, ms", "free_p99"),
        ("500 honest + 100 hostile: calls/s", "rate"),
        ("  p99 of one call, ms", "p99"),
        ("answer during 4 x 64 MiB bodies: median ms", "bodies"),
        ("answer with 1100 trickling heads: median ms", "heads"),
        (f"master.log after {log_calls} x 1 MiB caller_id, MB", "log"),
    ]
    print(f"\n{'load under attack (issue 18)':46} {'minros':>16} {'Debian':>16}")
    print("-" * 80)
    for label, key in rows:
        print(f"{label:46} {cell(kinds[0], key):>16} {cell(kinds[1], key):>16}")
    print(f"\nmedians of {reps} fresh runs, the masters measured in turn; hostile: 50 connections "
          "trickling a header\na byte per 0.2 s, 50 announcing 64 MiB and sending a byte a second; "
          "answers: getSystemState on a\nfresh connection (answered/asked); honest clients: "
          f"threads in 4 processes, {calls} getParam each on\nkept-alive connections; 2 shared cores")


def main(argv: List[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    parser.add_argument("--only-load", action="store_true",
                        help="only the load under attack (issue 18)")
    parser.add_argument("--baseline", default="", metavar="PY",
                        help="add the master run by this interpreter (another checkout's venv)")
    args = parser.parse_args(argv)
    if not os.path.exists("/usr/bin/rosmaster"):
        print("Debian's rosmaster is not installed: nothing to compare with", file=sys.stderr)
        return 1
    byte_compile_minros()
    base = bool(args.baseline)
    if base:
        MASTERS["baseline master"] = ([args.baseline, "-m", "minros.master", "-p", "{port}"], False)
        MASTERS["baseline core"] = ([args.baseline, "-m", "minros", "core", "-p", "{port}"], False)
        # its checkout, when the interpreter is that checkout's .venv
        byte_compile_minros(os.path.dirname(os.path.dirname(os.path.dirname(
            os.path.abspath(args.baseline)))))
    if args.only_load:
        load_section(args.quick)
        return 0
    reps = 1 if args.quick else 3
    rows: List[Tuple[str, str, float, float, float]] = []  # (metric, unit, minros, debian, base)
    with tempfile.TemporaryDirectory() as home:
        os.makedirs(os.path.join(home, "log"))

        def startup(kind: str) -> float:
            samples = []
            for _ in range(reps):
                m = Running(kind, home)
                samples.append(m.first_answer)
                m.stop()
            return statistics.median(samples)

        rows.append(("start to first answer: master", "ms", startup("minros master") * 1e3,
                     startup("Debian rosmaster") * 1e3,
                     startup("baseline master") * 1e3 if base else 0.0))
        rows.append(("start to first answer: core", "ms", startup("minros core") * 1e3,
                     startup("Debian roscore") * 1e3,
                     startup("baseline core") * 1e3 if base else 0.0))

        # Both masters run side by side; every repetition uses fresh ones and measures them in
        # turn, and the table shows medians (a shared 2-core machine is noisy).
        samples: Dict[str, Dict[str, List[float]]] = {
            kind: {} for kind in ("minros master", "Debian rosmaster")
            + (("baseline master",) if base else ())}
        calls = 40 if args.quick else 100
        for _rep in range(reps):
            running = {kind: Running(kind, home) for kind in samples}
            try:
                for kind, m in running.items():
                    r = samples[kind]
                    r.setdefault("latency", []).append(one_call_latency(m, 500) * 1e6)
                    r.setdefault("reg200", []).append(register_publishers(m, 200, "a") * 1e3)
                    r.setdefault("reg2000", []).append(register_publishers(m, 2000, "b") * 1e3)
                    r.setdefault("state", []).append(system_state(m, 5 if args.quick else 20) * 1e3)
                for _ in range(3):
                    for kind, m in running.items():
                        samples[kind].setdefault("conc", []).append(
                            concurrent_clients(m, 50, calls) * 1e3)
            finally:
                for m in running.values():
                    m.stop()
        ours = {k: statistics.median(v) for k, v in samples["minros master"].items()}
        deb = {k: statistics.median(v) for k, v in samples["Debian rosmaster"].items()}
        old = {k: statistics.median(v) for k, v in samples.get("baseline master", {}).items()}
        for metric, unit, key in (("one getPid call (kept-alive)", "us", "latency"),
                                  ("register 200 publishers", "ms", "reg200"),
                                  ("register 2000 publishers", "ms", "reg2000"),
                                  ("getSystemState, 2200 topics", "ms", "state"),
                                  (f"50 clients x {calls} getParam", "ms", "conc")):
            rows.append((metric, unit, ours[key], deb[key], old.get(key, 0.0)))

    extra = f" {'baseline':>10} {'base/minros':>11}" if base else ""
    print(f"{'metric':34} {'unit':>4} {'minros':>10} {'Debian':>10} {'ratio':>7}{extra}")
    print("-" * (69 + len(extra)))
    for metric, unit, mine, theirs, older in rows:
        extra = f" {older:10.1f} {older / mine:10.2f}x" if base else ""
        print(f"{metric:34} {unit:>4} {mine:10.1f} {theirs:10.1f} {theirs / mine:6.2f}x{extra}")
    print(f"\n50 concurrent clients: minros {50 * calls / ours['conc'] * 1e3:.0f} calls/s, "
          f"Debian {50 * calls / deb['conc'] * 1e3:.0f} calls/s (clients are threads of one "
          f"Python process; medians of {reps} fresh runs; 2 shared cores)")
    load_section(args.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main())
