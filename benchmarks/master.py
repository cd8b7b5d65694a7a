"""Master benchmark: minros's master beside Debian's rosmaster (and roscore beside ``minros core``).

Run: ``.venv/bin/python benchmarks/master.py [--quick]``. Every measurement uses the same client
(Python's stdlib xmlrpc.client over one kept-alive connection per thread) against each master,
started fresh on a free loopback port, and prints one table. "ratio" = Debian time / minros time
(> 1 means minros is faster).
"""

from __future__ import annotations

import argparse
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


def main(argv: List[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    args = parser.parse_args(argv)
    if not os.path.exists("/usr/bin/rosmaster"):
        print("Debian's rosmaster is not installed: nothing to compare with", file=sys.stderr)
        return 1
    reps = 1 if args.quick else 3
    rows: List[Tuple[str, str, float, float]] = []  # (metric, unit, minros, debian)
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
                     startup("Debian rosmaster") * 1e3))
        rows.append(("start to first answer: core", "ms", startup("minros core") * 1e3,
                     startup("Debian roscore") * 1e3))

        # Both masters run side by side; every repetition uses fresh ones and measures them in
        # turn, and the table shows medians (a shared 2-core machine is noisy).
        samples: Dict[str, Dict[str, List[float]]] = {
            kind: {} for kind in ("minros master", "Debian rosmaster")}
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
        rows.append(("one getPid call (kept-alive)", "us", ours["latency"], deb["latency"]))
        rows.append(("register 200 publishers", "ms", ours["reg200"], deb["reg200"]))
        rows.append(("register 2000 publishers", "ms", ours["reg2000"], deb["reg2000"]))
        rows.append(("getSystemState, 2200 topics", "ms", ours["state"], deb["state"]))
        rows.append((f"50 clients x {calls} getParam", "ms", ours["conc"], deb["conc"]))

    print(f"{'metric':34} {'unit':>4} {'minros':>10} {'Debian':>10} {'ratio':>7}")
    print("-" * 69)
    for metric, unit, mine, theirs in rows:
        print(f"{metric:34} {unit:>4} {mine:10.1f} {theirs:10.1f} {theirs / mine:6.2f}x")
    print(f"\n50 concurrent clients: minros {50 * calls / ours['conc'] * 1e3:.0f} calls/s, "
          f"Debian {50 * calls / deb['conc'] * 1e3:.0f} calls/s (clients are threads of one "
          f"Python process; medians of {reps} fresh runs; 2 shared cores)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
