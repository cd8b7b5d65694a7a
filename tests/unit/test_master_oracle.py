"""Differential test: random API call sequences through Debian's ROSMasterHandler (in-process,
run by /usr/bin/python3, callbacks recorded instead of sent) and minros's MasterHandler.

Every result triplet and every callback the master would make (publisherUpdate, paramUpdate,
shutdown of a bumped node) must be identical. No sockets; thousands of calls in one batch.
"""

from __future__ import annotations

import json
import random
import subprocess

import pytest

from minros.master import MasterHandler
from support import REFERENCE_PYTHON, reference_env, require_reference

# each test starts a process (see the slow marker in pyproject.toml)
pytestmark = pytest.mark.slow

_ORACLE = r"""
import json, sys
import rosmaster.master_api as api


class Recorder:
    def __init__(self):
        self.calls = []
    def queue_task(self, marker, task, args=None, callback=None):
        name = getattr(task, "__name__", "")
        if name == "publisher_update_task":
            node_api, topic, uris = args
            self.calls.append(["publisherUpdate", node_api, ["/master", topic, list(uris)]])
        elif name == "param_update_task":
            _cid, node_api, key, value = args
            # snapshot now: the queued value is the live tree object in rosmaster
            self.calls.append(json.loads(json.dumps(
                ["paramUpdate", node_api, ["/master", key, value]])))
        elif name == "shutdown_node_task":
            node_api, caller_id, reason = args
            self.calls.append(["shutdown", node_api,
                               ["/master", "[{}] Reason: {}".format(caller_id, reason)]])
        else:
            self.calls.append(["?", name])
    def join_all(self, *a, **k):
        pass

h = api.ROSMasterHandler(num_workers=1)
h.thread_pool.join_all(wait_for_tasks=False, wait_for_threads=False)
rec = Recorder()
h.thread_pool = rec
h.reg_manager.thread_pool = rec
out = []
for method, args in json.load(sys.stdin):
    result = getattr(h, method)(*args)
    calls, rec.calls = rec.calls, []
    out.append([json.loads(json.dumps(list(result))), calls])
print(json.dumps(out))
"""


class Recorder:
    def __init__(self) -> None:
        self.calls = []

    def queue(self, node_api, method, args, coalesce=None, on_result=None):
        self.calls.append([method, node_api, list(args)])


CALLERS = ["/n1", "/ns/n2", "/ns/sub/n3", "/n1", "rel", ""]
APIS = ["http://h1:1/", "http://h2:1/", "http://h3:1/"]
KEYS = ["a", "/a", "/a/b", "a/b/c", "~p", "~p/q", "/ns/x", "x", "/ns/sub", "b/", "/", "",
        "//a//b/", "a b", 3]
TOPICS = ["t", "/t", "~t", "/ns/t", "sub/t", "", "/", "a:b", 7]
TYPES = ["std_msgs/String", "*", "a/B", "bad"]


def _value(rng: random.Random, depth: int = 0):
    kind = rng.randrange(6 if depth < 2 else 4)
    if kind == 0:
        return rng.randint(-5, 5)
    if kind == 1:
        return rng.choice(["s", "", "ü"])
    if kind == 2:
        return rng.choice([True, False])
    if kind == 3:
        return [rng.randint(0, 3) for _ in range(rng.randrange(3))]
    return {rng.choice("bcpqx"): _value(rng, depth + 1) for _ in range(rng.randrange(4))}


def _ops(seed: int, count: int):
    rng = random.Random(seed)
    ops = []
    for _ in range(count):
        caller = rng.choice(CALLERS)
        api = rng.choice(APIS)
        choice = rng.randrange(20)
        key = rng.choice(KEYS)
        topic = rng.choice(TOPICS)
        if choice < 3:
            ops.append(["setParam", [caller, key, _value(rng)]])
        elif choice == 3:
            ops.append(["deleteParam", [caller, key]])
        elif choice == 4:
            ops.append(["getParam", [caller, key]])
        elif choice == 5:
            ops.append(["hasParam", [caller, key]])
        elif choice == 6:
            ops.append(["searchParam", [caller, key]])
        elif choice == 7:
            ops.append(["subscribeParam", [caller, api, key]])
        elif choice == 8:
            ops.append(["unsubscribeParam", [caller, api, key]])
        elif choice == 9:
            ops.append(["registerPublisher", [caller, topic, rng.choice(TYPES), api]])
        elif choice == 10:
            ops.append(["registerSubscriber", [caller, topic, rng.choice(TYPES), api]])
        elif choice == 11:
            ops.append(["unregisterPublisher", [caller, topic, api]])
        elif choice == 12:
            ops.append(["unregisterSubscriber", [caller, topic, api]])
        elif choice == 13:
            ops.append(["registerService", [caller, topic, f"rosrpc://{api[7:9]}:2", api]])
        elif choice == 14:
            ops.append(["unregisterService", [caller, topic, f"rosrpc://{rng.choice(APIS)[7:9]}:2"]])
        elif choice == 15:
            ops.append(["lookupNode", [caller, rng.choice(CALLERS + ["n1", "n2"])]])
        elif choice == 16:
            ops.append(["lookupService", [caller, topic]])
        elif choice == 17:
            ops.append(["getPublishedTopics", [caller, rng.choice(["", "/ns", "ns", "/"])]])
        elif choice == 18:
            ops.append([rng.choice(["getSystemState", "getTopicTypes", "getParamNames"]), [caller]])
        else:
            ops.append(["getParam", [caller, "/"]])
    return ops


@pytest.mark.parametrize("seed", range(1, 7))
def test_random_call_sequences_match_rosmaster(seed):
    require_reference()
    ops = _ops(seed, 800)
    proc = subprocess.run([REFERENCE_PYTHON, "-c", _ORACLE], input=json.dumps(ops), text=True,
                          capture_output=True, env=reference_env({}), timeout=60)
    assert proc.returncode == 0, proc.stderr[-3000:]
    expected = json.loads(proc.stdout)
    rec = Recorder()
    handler = MasterHandler(rec)
    for index, ((method, args), (exp_result, exp_calls)) in enumerate(zip(ops, expected)):
        result = json.loads(json.dumps(getattr(handler, method)(*args)))
        calls, rec.calls = json.loads(json.dumps(rec.calls)), []
        assert [result, calls] == [exp_result, exp_calls], (
            f"call {index}: {method}{tuple(args)}\n  rosmaster: {exp_result} {exp_calls}\n"
            f"  minros:    {result} {calls}\nhistory: {ops[max(0, index - 8):index]}")
    assert len(expected) == len(ops)
