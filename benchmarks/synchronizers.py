"""message_filters benchmark: ApproximateTimeSynchronizer throughput, minros beside ROS 1's.

Run: ``.venv/bin/python benchmarks/synchronizers.py [--quick]``. Each round runs one worker
process per implementation (minros's stand-in under this venv, ROS 1's message_filters under
Debian's /usr/bin/python3), alternating, on the same generated streams; a worker feeds the
messages straight into the synchronizer's inputs (no sockets) and reports the time. The table
gives the median messages per second over the rounds; "ratio" = minros rate / ROS 1 rate.
Both produce the same output sets (tests/interop/test_message_filters_interop.py checks it).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import time

from _bytecode import byte_compile_minros  # benchmarks/ is the script's directory: on sys.path

REFERENCE_PYTHON = "/usr/bin/python3"


def scenarios(quick: bool) -> list:
    rng = random.Random(3)
    scale = 0.25 if quick else 1.0

    def periodic(rates, seconds, jitter, slop, queue):
        events = []
        for index, hz in enumerate(rates):
            t = 1.0
            while t < 1.0 + seconds * scale:
                stamp = t + rng.uniform(-jitter, jitter)
                events.append((stamp + rng.uniform(0, 0.01), index, stamp))
                t += 1.0 / hz
        events.sort()
        return {"inputs": len(rates), "queue": queue, "slop": slop,
                "events": [[i, s] for _a, i, s in events]}

    def unmatchable(inputs, count, queue):
        # Around each message of input 0, every other input has a full queue within the slop,
        # but the odd inputs run 75 ms early and the even ones 75 ms late, so no set spans less
        # than the slop: the search tries every combination (ROS 1) or gives up on each pair
        # of early/late candidates at once (minros). A clock offset's worst case.
        events = []
        for n in range(int(count * scale)):
            base = 1.0 + n * 0.001
            for index in range(inputs):
                offset = 0.0 if index == 0 else -0.075 if index % 2 else 0.075
                events.append([index, base + offset + rng.uniform(-0.0002, 0.0002)])
        return {"inputs": inputs, "queue": queue, "slop": 0.1, "events": events}

    return [
        ("camera + info, 30 Hz, slop 10 ms", periodic([30, 30], 120, 0.003, 0.01, 10)),
        ("laser 40 + odom 50 + imu 200 Hz", periodic([40, 50, 200], 60, 0.004, 0.01, 10)),
        ("3 inputs, nothing matches, queue 10", unmatchable(3, 600, 10)),
        ("4 inputs, nothing matches, queue 10", unmatchable(4, 300, 10)),
    ]


def worker(path: str) -> None:
    """Time feeding each scenario of ``path`` into this interpreter's message_filters."""
    import message_filters
    import rospy
    from std_msgs.msg import Header

    # no node: both read the wall clock the same way (rospy.Time.now needs init_node)
    rospy.Time.now = staticmethod(lambda: rospy.Time.from_sec(time.time()))

    class Stamped:
        __slots__ = ("header",)

        def __init__(self, secs: float) -> None:
            self.header = Header(stamp=rospy.Time.from_sec(secs))

    results = []
    for spec in json.load(open(path)):
        sources = [message_filters.SimpleFilter() for _ in range(spec["inputs"])]
        sync = message_filters.ApproximateTimeSynchronizer(sources, spec["queue"], spec["slop"])
        out: list = []
        sync.registerCallback(lambda *msgs, _out=out: _out.append(1))
        msgs = [(sources[i], Stamped(s)) for i, s in spec["events"]]
        start = time.perf_counter()
        for source, msg in msgs:
            source.signalMessage(msg)
        elapsed = time.perf_counter() - start
        results.append({"seconds": elapsed, "count": len(msgs), "sets": len(out)})
    print(json.dumps(results))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter streams, fewer rounds")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.worker)
        return
    byte_compile_minros()
    named = scenarios(args.quick)
    import tempfile

    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump([spec for _name, spec in named], f)
        path = f.name
    contenders = {"minros": [sys.executable],
                  "ROS 1": [REFERENCE_PYTHON]}
    env_ref = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env_ref["PATH"] = "/usr/bin:/bin"
    rates = {name: [[] for _ in named] for name in contenders}
    sets = {}
    rounds = 3 if args.quick else 5
    try:
        for _round in range(rounds):
            for name, argv in contenders.items():
                if name == "ROS 1" and not os.path.exists(REFERENCE_PYTHON):
                    continue
                done = subprocess.run([*argv, __file__, "--worker", path], capture_output=True,
                                      text=True, timeout=600,
                                      env=env_ref if name == "ROS 1" else None)
                if done.returncode != 0:
                    sys.exit(f"{name} worker failed: {done.stderr.strip().splitlines()[-1:]}")
                for i, result in enumerate(json.loads(done.stdout)):
                    rates[name][i].append(result["count"] / result["seconds"])
                    sets.setdefault(i, {})[name] = result["sets"]
    finally:
        os.unlink(path)
    print(f"{'scenario':40} {'messages':>8} {'sets':>6} {'minros msg/s':>13} {'ROS 1 msg/s':>12} "
          f"{'ratio':>6}")
    for i, (label, spec) in enumerate(named):
        ours = statistics.median(rates["minros"][i])
        ref = statistics.median(rates["ROS 1"][i]) if rates["ROS 1"][i] else float("nan")
        same = "" if len(set(sets[i].values())) == 1 else "  (different outputs!)"
        print(f"{label:40} {len(spec['events']):8d} {sets[i]['minros']:6d} {ours:13.0f} "
              f"{ref:12.0f} {ours / ref:6.2f}{same}")


if __name__ == "__main__":
    main()
