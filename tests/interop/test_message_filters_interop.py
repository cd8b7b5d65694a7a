"""message_filters: minros's outputs equal ROS 1's (Debian python3-message-filters) on the same
recorded input streams: exact and approximate synchronisation, queue overflow, headerless
messages, Cache queries. Both implementations run tests/interop/message_filters_feed.py on one
scenario file; every output set and its order must match."""

from __future__ import annotations

import json
import random
import subprocess
from pathlib import Path

import pytest

from support import PYTHON, REFERENCE_PYTHON, reference_env, require_reference

pytestmark = pytest.mark.interop

FEED = Path(__file__).resolve().parent / "message_filters_feed.py"


def _periodic(rng: random.Random, inputs_hz, seconds: float, jitter_ms: float, drop: float):
    """Events of sensors at the given rates, stamped with jitter, some dropped, arrival order
    shuffled a little (transport delays differ per topic)."""
    events = []
    for index, hz in enumerate(inputs_hz):
        t = 1.0
        while t < 1.0 + seconds:
            if rng.random() >= drop:
                stamp = t + rng.uniform(-jitter_ms, jitter_ms) / 1000.0
                arrival = stamp + rng.uniform(0.0, 0.02)
                events.append((arrival, index, stamp))
            t += 1.0 / hz
    events.sort()
    return [[i, int(s), int(round((s - int(s)) * 1e9))] for _a, i, s in events]


def _random(rng: random.Random, inputs: int, count: int, stamps: int, headerless: float = 0.0):
    """Events whose stamps come from a small set (duplicates, ties, disorder)."""
    pool = [(rng.randint(0, 3), rng.choice([0, 100000000, 250000000, 500000000, 500000001]))
            for _ in range(stamps)]
    events = []
    for _ in range(count):
        if rng.random() < headerless:
            events.append([rng.randrange(inputs), None])
        else:
            secs, nsecs = rng.choice(pool)
            events.append([rng.randrange(inputs), secs, nsecs])
    return events


def scenarios():
    rng = random.Random(13)
    out = [
        {"name": "exact 2 inputs", "filter": "exact", "inputs": 2, "queue_size": 10,
         "events": _random(rng, 2, 300, 12)},
        {"name": "exact 3 inputs overflow", "filter": "exact", "inputs": 3, "queue_size": 3,
         "events": _random(rng, 3, 300, 20)},
        {"name": "camera+info", "filter": "approx", "inputs": 2, "queue_size": 5, "slop": 0.01,
         "events": _periodic(rng, [30, 30], 5, 4, 0.1)},
        {"name": "laser+odom+imu", "filter": "approx", "inputs": 3, "queue_size": 10,
         "slop": 0.015, "events": _periodic(rng, [40, 50, 100], 4, 3, 0.05)},
        {"name": "random approx ties", "filter": "approx", "inputs": 3, "queue_size": 4,
         "slop": 0.3, "events": _random(rng, 3, 400, 15)},
        {"name": "random approx small queue", "filter": "approx", "inputs": 2, "queue_size": 2,
         "slop": 1.0, "events": _random(rng, 2, 300, 30)},
        {"name": "slop zero", "filter": "approx", "inputs": 2, "queue_size": 5, "slop": 0.0,
         "events": _random(rng, 2, 50, 3)},
        {"name": "headerless allowed", "filter": "approx", "inputs": 2, "queue_size": 5,
         "slop": 0.0025, "allow_headerless": True, "events": _random(rng, 2, 200, 5, 0.7)},
        {"name": "headerless refused", "filter": "approx", "inputs": 2, "queue_size": 5,
         "slop": 0.5, "events": _random(rng, 2, 100, 5, 0.3)},
        {"name": "cache", "filter": "cache", "inputs": 1, "queue_size": 5,
         "allow_headerless": True, "events": _random(rng, 1, 120, 10, 0.2)},
    ]
    return out


def _feed(python: str, env, scenario_file: Path):
    done = subprocess.run([python, str(FEED), str(scenario_file)], env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return [json.loads(line) for line in done.stdout.splitlines()]


def test_outputs_equal_ros1_on_the_same_streams(tmp_path: Path):
    require_reference()
    scenario_file = tmp_path / "scenarios.json"
    all_scenarios = scenarios()
    scenario_file.write_text(json.dumps(all_scenarios))
    reference = _feed(REFERENCE_PYTHON, reference_env({}), scenario_file)
    ours = _feed(PYTHON, None, scenario_file)
    assert len(reference) == len(all_scenarios)
    for ref, got in zip(reference, ours):
        assert got == ref, ref["name"]
    by_name = {r["name"]: r for r in reference}
    # the streams exercise what they claim: matches found, overflow and slop limits hit
    assert len(by_name["camera+info"]["outputs"]) > 100
    assert len(by_name["laser+odom+imu"]["outputs"]) > 20
    assert by_name["slop zero"]["outputs"] == []
    assert by_name["headerless allowed"]["outputs"]
    assert by_name["cache"]["queries"][-1][2]


def test_match_search_equals_trying_every_combination():
    """The pruned search picks what itertools.product order would pick (ROS 1's method)."""
    import itertools

    from minros.message_filters import match_within

    rng = random.Random(7)
    for _ in range(3000):
        lists = [[(f"s{i}{j}", rng.randint(0, 40)) for j in range(rng.randint(1, 4))]
                 for i in range(rng.randint(1, 3))]
        fixed = rng.choice([None, rng.randint(0, 40)])
        slop = rng.randint(0, 15)
        expected = None
        for combo in itertools.product(*lists):
            values = [ns for _s, ns in combo] + ([] if fixed is None else [fixed])
            if max(values) - min(values) < slop:
                expected = [s for s, _ns in combo]
                break
        assert match_within(lists, slop, fixed) == expected
