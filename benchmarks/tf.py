#!/usr/bin/env python3
"""tf benchmark: minros's pure-Python tf2 beside Debian's C++ tf2_py (BufferCore) and tf2_ros.

    .venv/bin/python benchmarks/tf.py [--rounds 3] [--seconds 1] [--listen 5]

Scenarios, contenders interleaved round by round (median of the rounds shown):

* lookups per second on a 10-link chain f0 -> f10, every link with 100 samples 0.1 s apart,
  at 1000 random times between samples (so every link is interpolated), through the core
  (``lookup_transform_core``) and through tf2_ros's ``Buffer.lookup_transform``; and at time 0
  (the latest common time). minros runs in this process; Debian's tf2_py.BufferCore runs
  under /usr/bin/python3 with the same inserts and queries (minros.tf.testing's oracle);
* the CPU a tf2_ros listener process (Buffer + TransformListener) uses while one publisher
  sends 100 frames in one tf2_msgs/TFMessage at 100 Hz (10,000 transforms/s): minros's
  listener, then Debian's, against the same publisher, each measured over ``--listen``
  seconds after a 2 s warm-up; the frames/rate columns show both really kept up.

Targets (issue 12): at least 20,000 lookups/s, the listener below 25 % of one core.
``--profile`` prints where a minros lookup spends its time (cProfile).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from typing import Any, List

from _bytecode import byte_compile_minros  # benchmarks/ is the script's directory: on sys.path

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
VENV_PYTHON = os.path.join(REPO, ".venv", "bin", "python")
REFERENCE_PYTHON = "/usr/bin/python3"
FRAMES = 100  # listener scenario: frames per message
RATE = 100  # listener scenario: messages per second


# --------------------------------------------------------------------------------- lookups

def chain_script(links: int = 10, samples: int = 100, queries: int = 1000, seed: int = 1):
    """Inserts (oracle action format) and query times of the chain scenario."""
    rnd = random.Random(seed)
    actions = []
    for i in range(links):
        for k in range(samples):
            raw = [rnd.uniform(-1, 1) for _ in range(4)]
            n = sum(c * c for c in raw) ** 0.5
            secs, tenth = divmod(k, 10)
            actions.append(["set", f"f{i}", f"f{i + 1}", [100 + secs, tenth * 100_000_000],
                            [rnd.uniform(-1, 1) for _ in range(3)], [c / n for c in raw],
                            "/bench", False])
    times = []
    for _ in range(queries):
        k = rnd.randrange(samples - 1)
        secs, tenth = divmod(k, 10)
        times.append([100 + secs, tenth * 100_000_000 + rnd.randrange(1, 100_000_000)])
    return actions, times


def minros_lookups(actions, times, seconds: float, api: str) -> float:
    import minros
    from minros.msgs.testing import best_rate
    from minros.tf.buffer import Buffer
    from minros.tf.core import BufferCore
    from minros.tf.testing import play

    core = Buffer(debug=False) if api == "buffer" else BufferCore()
    play(core, actions)
    stamps = [minros.Time(s, n) for s, n in times]
    lookup = core.lookup_transform if api == "buffer" else core.lookup_transform_core

    def one_pass() -> None:
        for t in stamps:
            lookup("f0", "f10", t)

    return best_rate(one_pass, seconds, 0.01) * len(stamps)


# run by Debian's interpreter after minros.msgs.testing.reference_script's best_rate
BUFFER_BENCH = r'''
import json, sys
import rospy, tf2_ros
from geometry_msgs.msg import TransformStamped
req = json.loads(sys.stdin.readline())
buf = tf2_ros.Buffer(debug=False)
for a in req["actions"]:
    m = TransformStamped()
    m.header.frame_id, m.child_frame_id = a[1], a[2]
    m.header.stamp = rospy.Time(*a[3])
    m.transform.translation.x, m.transform.translation.y, m.transform.translation.z = a[4]
    r = m.transform.rotation
    r.x, r.y, r.z, r.w = a[5]
    buf.set_transform(m, a[6])
stamps = [rospy.Time(s, n) for s, n in req["times"]]
def one_pass():
    for t in stamps:
        buf.lookup_transform("f0", "f10", t)
print(json.dumps({"rate": best_rate(one_pass, req["seconds"], 0.01) * len(stamps)}))
'''


def debian_buffer_lookups(actions, times, seconds: float, env: dict) -> float:
    from minros.msgs.testing import reference_script

    done = subprocess.run([REFERENCE_PYTHON, "-c", reference_script(BUFFER_BENCH)], env=env, capture_output=True,
                          text=True, timeout=120,
                          input=json.dumps({"actions": actions, "times": times, "seconds": seconds}) + "\n")
    return json.loads(done.stdout.splitlines()[-1])["rate"]


# --------------------------------------------------------------------------------- listener

def role_publisher(args) -> None:
    import rospy
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage

    rospy.init_node("tf_bench_caster")
    pub = rospy.Publisher("/tf", TFMessage, queue_size=10)
    transforms = []
    for i in range(FRAMES):
        t = TransformStamped()
        t.header.frame_id = "base"
        t.child_frame_id = f"link{i}"
        t.transform.translation.x = float(i)
        t.transform.rotation.w = 1.0
        transforms.append(t)
    print(json.dumps({"ready": True}), flush=True)
    rate = rospy.Rate(RATE)
    while not rospy.is_shutdown():
        now = rospy.Time.now()
        for t in transforms:
            t.header.stamp = now
        pub.publish(TFMessage(transforms))
        rate.sleep()


def role_listener(args) -> None:
    """Buffer + TransformListener; prints its CPU share over ``--listen`` seconds."""
    import yaml

    import rospy
    import tf2_ros

    rospy.init_node("tf_bench_listener", anonymous=True)
    buf = tf2_ros.Buffer(debug=False)
    tf2_ros.TransformListener(buf)
    deadline = time.time() + 20
    while time.time() < deadline and len(yaml.safe_load(buf.all_frames_as_yaml()) or {}) < FRAMES:
        time.sleep(0.05)
    time.sleep(2.0)  # warm-up: connections settled, caches at their steady length
    wall0, cpu0 = time.perf_counter(), time.process_time()
    time.sleep(args.listen)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    frames = yaml.safe_load(buf.all_frames_as_yaml()) or {}
    rates = [f["rate"] for f in frames.values()]
    lag = rospy.get_time() - max((f["most_recent_transform"] for f in frames.values()), default=0)
    print(json.dumps({"cpu": 100.0 * cpu / wall, "frames": len(frames),
                      "rate": statistics.median(rates) if rates else 0.0, "lag": lag}), flush=True)


ROLES = {"publisher": role_publisher, "listener": role_listener}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Listening:
    """A master and the publisher, for the listener scenario."""

    def __init__(self, reference: bool, python: str) -> None:
        self.home = tempfile.mkdtemp(prefix="minros-bench-tf-")
        self.port = _free_port()
        self.reference = reference
        self.python = python
        master = (["/usr/bin/rosmaster", "--core", "-p", str(self.port)] if reference
                  else [python, "-m", "minros.master", "-p", str(self.port)])
        self.master = subprocess.Popen(master, env=self.env(reference), stdout=subprocess.DEVNULL,
                                       stderr=subprocess.DEVNULL)
        time.sleep(1.5)
        self.publisher = subprocess.Popen([python, os.path.abspath(__file__), "--role", "publisher"],
                                          env=self.env(False), stdout=subprocess.PIPE,
                                          stderr=subprocess.DEVNULL, text=True)
        if "ready" not in self.publisher.stdout.readline():
            raise RuntimeError("the publisher did not start")

    def env(self, reference: bool) -> dict:
        env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_") and k != "PYTHONPATH"}
        env.update(ROS_MASTER_URI=f"http://localhost:{self.port}", ROS_HOSTNAME="localhost",
                   ROS_HOME=self.home, ROS_LOG_DIR=os.path.join(self.home, "log"))
        if reference:
            env.pop("VIRTUAL_ENV", None)
            env["PATH"] = "/usr/bin:/bin"
        return env

    def listen(self, who: str, seconds: float) -> dict:
        python = REFERENCE_PYTHON if who == "debian" else self.python
        done = subprocess.run([python, os.path.abspath(__file__), "--role", "listener",
                               "--listen", str(seconds)], env=self.env(who == "debian"),
                              capture_output=True, text=True, timeout=seconds + 60)
        lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
        if not lines:
            raise RuntimeError(f"{who} listener failed: {done.stderr[-500:]}")
        return json.loads(lines[-1])

    def close(self) -> None:
        for proc in (self.publisher, self.master):
            proc.terminate()
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                proc.kill()
        shutil.rmtree(self.home, ignore_errors=True)


# --------------------------------------------------------------------------------- main

def _reference_env() -> dict:
    env = dict(os.environ)
    for key in ("VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME"):
        env.pop(key, None)
    env["PATH"] = "/usr/bin:/bin"
    return env


def _has_reference() -> bool:
    return os.path.exists(REFERENCE_PYTHON) and subprocess.run(
        [REFERENCE_PYTHON, "-c", "import tf2_py, tf2_ros"], env=_reference_env(),
        capture_output=True).returncode == 0


def _fmt(value: Any, digits: int = 0) -> str:
    if value is None:
        return "—"
    return f"{value:,.{digits}f}"


def profile(actions, times) -> None:
    import cProfile
    import pstats

    import minros
    from minros.tf.core import BufferCore
    from minros.tf.testing import play

    core = BufferCore()
    play(core, actions)
    stamps = [minros.Time(s, n) for s, n in times]
    lookup = core.lookup_transform_core
    profiler = cProfile.Profile()
    profiler.enable()
    for _ in range(20):
        for t in stamps:
            lookup("f0", "f10", t)
    profiler.disable()
    pstats.Stats(profiler).sort_stats("tottime").print_stats(12)


def main(argv: List[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--role", choices=sorted(ROLES), help=argparse.SUPPRESS)
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds (median shown)")
    parser.add_argument("--seconds", type=float, default=1.0, help="per lookup measurement")
    parser.add_argument("--listen", type=float, default=5.0, help="seconds of listener CPU sampling")
    parser.add_argument("--minros-python", default=VENV_PYTHON, help="interpreter for minros workers")
    parser.add_argument("--profile", action="store_true", help="profile minros's lookups and exit")
    args = parser.parse_args(argv)
    if args.role:
        ROLES[args.role](args)
        return 0
    byte_compile_minros()
    actions, times = chain_script()
    zero = [[0, 0]] * len(times)
    if args.profile:
        profile(actions, times)
        return 0
    reference = _has_reference()
    oracle = None
    if reference:
        from minros.tf.testing import TfOracle

        oracle = TfOracle(env=_reference_env())
    rows = {key: {"minros": [], "debian": []} for key in ("core", "buffer", "zero", "cpu")}
    checks = {"minros": [], "debian": []}
    listening = Listening(reference, args.minros_python)
    try:
        for rnd in range(args.rounds):
            for who in ("minros", "debian"):
                if who == "debian" and not reference:
                    continue
                if who == "minros":
                    core = minros_lookups(actions, times, args.seconds, "core")
                    buffer = minros_lookups(actions, times, args.seconds, "buffer")
                    latest = minros_lookups(actions, zero, args.seconds, "core")
                else:
                    queries = [["f0", "f10", t] for t in times]
                    core = oracle.bench(actions, queries, args.seconds)
                    buffer = debian_buffer_lookups(actions, times, args.seconds, _reference_env())
                    latest = oracle.bench(actions, [["f0", "f10", [0, 0]]] * len(times), args.seconds)
                heard = listening.listen(who, args.listen)
                for key, value in (("core", core), ("buffer", buffer), ("zero", latest),
                                   ("cpu", heard["cpu"])):
                    rows[key][who].append(value)
                checks[who].append(heard)
                print(f"round {rnd + 1} {who:6} core {core:,.0f}/s buffer {buffer:,.0f}/s "
                      f"time-0 {latest:,.0f}/s listener {heard['cpu']:.1f} % CPU "
                      f"({heard['frames']} frames at {heard['rate']:.0f} Hz, lag {heard['lag'] * 1000:.0f} ms)",
                      file=sys.stderr, flush=True)
    finally:
        listening.close()
        if oracle is not None:
            oracle.close()

    def med(key: str, who: str):
        values = rows[key][who]
        return statistics.median(values) if values else None

    table = [
        ("lookups/s, 10-link chain, interpolated (core)", "core", 0, "≥ 20,000"),
        ("lookups/s, same, tf2_ros Buffer.lookup_transform", "buffer", 0, "≥ 20,000"),
        ("lookups/s, same chain at time 0 (latest common)", "zero", 0, ""),
        (f"listener CPU, {FRAMES} frames at {RATE} Hz (% of a core)", "cpu", 1, "< 25"),
    ]
    header = ["scenario", "minros", "Debian (C++ core)", "minros/Debian", "target"]
    out = []
    for title, key, digits, target in table:
        a, b = med(key, "minros"), med(key, "debian")
        out.append([title, _fmt(a, digits), _fmt(b, digits),
                    f"{a / b:.2f}x" if a and b else "—", target])
    kept = {who: (min(c["frames"] for c in checks[who]), statistics.median(c["rate"] for c in checks[who]))
            for who in checks if checks[who]}
    widths = [max(len(str(r[i])) for r in [header] + out) for i in range(len(header))]
    python = subprocess.run([args.minros_python, "-c", "import sys; print(sys.version.split()[0])"],
                            capture_output=True, text=True).stdout.strip()
    print(f"tf benchmark: {args.rounds} interleaved rounds, median; {os.cpu_count()} CPUs; "
          f"minros on Python {python}; master: {'Debian rosmaster' if reference else 'minros'}")
    print("| " + " | ".join(h.ljust(w) for h, w in zip(header, widths)) + " |")
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for row in out:
        print("| " + " | ".join(str(c).ljust(w) for c, w in zip(row, widths)) + " |")
    for who, (frames, rate) in kept.items():
        print(f"{who} listener kept {frames} frames at a median {rate:.0f} Hz each")
    return 0


if __name__ == "__main__":
    sys.exit(main())
