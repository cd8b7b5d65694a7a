"""Feed recorded message streams through whichever ``message_filters`` this interpreter has.

Run by tests/interop/test_message_filters_interop.py under Debian's /usr/bin/python3 (ROS 1's
message_filters on real rospy) and under minros's venv (the stand-in), with the same JSON
scenario file; prints one JSON line per scenario with everything the filters output, so the
two runs can be compared line for line.

A scenario: {"name", "filter": "exact"|"approx"|"cache", "inputs": N, "queue_size",
"slop", "allow_headerless", "events": [[input, secs, nsecs] or [input, null] (headerless)]}.
Event i carries id i; ROS time is a fake clock advanced 1 ms per event, so headerless
messages get deterministic stamps.
"""

from __future__ import annotations

import json
import sys

import message_filters
import rospy
from geometry_msgs.msg import PointStamped
from std_msgs.msg import Int32

CLOCK = [rospy.Time(1000, 0)]


def fake_now():
    return CLOCK[0]


def run(scenario):
    rospy.Time.now = staticmethod(fake_now)
    outputs = []
    sources = [message_filters.SimpleFilter() for _ in range(scenario["inputs"])]
    kind = scenario["filter"]
    if kind == "exact":
        sync = message_filters.TimeSynchronizer(sources, scenario["queue_size"])
    elif kind == "approx":
        sync = message_filters.ApproximateTimeSynchronizer(
            sources, scenario["queue_size"], scenario["slop"],
            allow_headerless=scenario.get("allow_headerless", False))
    else:
        sync = message_filters.Cache(sources[0], scenario["queue_size"],
                                     allow_headerless=scenario.get("allow_headerless", False))

    def collect(*msgs):
        outputs.append([_id(m) for m in msgs])

    sync.registerCallback(collect)
    queries = []
    for index, event in enumerate(scenario["events"]):
        CLOCK[0] = rospy.Time(1000, 0) + rospy.Duration(0, 1000000 * (index + 1))
        if event[1] is None:
            msg = Int32(data=index)
        else:
            msg = PointStamped()
            msg.header.stamp = rospy.Time(event[1], event[2])
            msg.point.x = index
        sources[event[0]].signalMessage(msg)
        if kind == "cache":
            queries.append(_cache_queries(sync, event))
    return {"name": scenario["name"], "outputs": outputs, "queries": queries}


def _id(msg):
    return int(msg.data) if hasattr(msg, "data") else int(msg.point.x)


def _cache_queries(cache, event):
    if event[1] is None:
        probe = CLOCK[0]
    else:
        probe = rospy.Time(event[1], event[2])
    latest = cache.getLatestTime()
    oldest = cache.getOldestTime()
    window = cache.getInterval(probe - rospy.Duration(0, 50000000), probe) if latest else []
    after = cache.getElemAfterTime(probe)
    before = cache.getElemBeforeTime(probe)
    last = cache.getLast()
    return [
        None if latest is None else latest.to_nsec(),
        None if oldest is None else oldest.to_nsec(),
        [_id(m) for m in window],
        None if after is None else _id(after),
        None if before is None else _id(before),
        None if last is None else _id(last),
    ]


def main():
    with open(sys.argv[1]) as f:
        scenarios = json.load(f)
    # ROS 1's rospy refuses Time.now() before init_node; the fake clock replaces it anyway
    if hasattr(rospy.rostime, "set_rostime_initialized"):
        rospy.rostime.set_rostime_initialized(True)
    for scenario in scenarios:
        print(json.dumps(run(scenario), sort_keys=True), flush=True)


if __name__ == "__main__":
    main()
