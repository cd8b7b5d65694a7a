"""Drive whichever ``diagnostic_updater`` this interpreter has through one fixed scenario.

Run by tests/interop/test_diagnostic_updater_interop.py under Debian's /usr/bin/python3 (ROS
1's diagnostic_updater on rospy) and under minros's venv; prints every DiagnosticArray the
Updater publishes as one JSON line, so the two runs can be compared. ROS time is a fake clock
the scenario advances; no master is needed (the publishers are replaced by recorders).
"""

from __future__ import annotations

import json

import diagnostic_updater as du
import rospy
from geometry_msgs.msg import PointStamped

CLOCK = [rospy.Time(100, 0)]
rospy.Time.now = staticmethod(lambda: CLOCK[0])


def _no_master(name, default=None):
    return default


rospy.get_param_cached = _no_master
try:  # minros: the rospy stand-in's functions are minros's
    import minros

    minros.get_param_cached = _no_master
except ImportError:
    pass


def advance(seconds):
    CLOCK[0] = CLOCK[0] + rospy.Duration.from_sec(seconds)


class Recorder:
    name = "/image"

    def __init__(self):
        self.sent = []

    def publish(self, msg):
        self.sent.append(msg)


def dump(array):
    return {"stamp": array.header.stamp.to_nsec(),
            "status": [[s.name, s.level, s.message, s.hardware_id,
                        [[kv.key, kv.value] for kv in s.values]] for s in array.status]}


def main():
    updater = du.Updater()
    published = Recorder()
    updater.publisher = published
    calls = []

    def checked(stat):
        calls.append(len(calls))
        if len(calls) % 2:
            stat.summary(du.WARN, f"odd call {len(calls)}")
        else:
            stat.summary(du.OK, "even call")
        stat.add("calls", len(calls))
        return stat

    updater.add(du.FunctionDiagnosticTask("checker", checked))
    updater.add("plain function", lambda stat: stat)  # leaves level 2 "No message was set"
    composite = du.CompositeDiagnosticTask("composite")
    composite.addTask(du.FunctionDiagnosticTask("a", lambda s: (s.summary(1, "a warns"), s)[1]))
    composite.addTask(du.FunctionDiagnosticTask("b", lambda s: (s.summary(2, "b fails"), s)[1]))
    composite.addTask(du.FunctionDiagnosticTask("c", lambda s: (s.add("c", 3.5), s)[1]))
    updater.add(composite)
    freq = du.FrequencyStatus(du.FrequencyStatusParam({"min": 9, "max": 11}, 0.1, 3))
    updater.add(freq)
    stamps = du.TimeStampStatus(du.TimeStampStatusParam(-1, 0.5))
    updater.add(stamps)
    headerless = du.HeaderlessTopicDiagnostic("chatter", updater,
                                              du.FrequencyStatusParam({"min": 5, "max": 5}))
    topic = du.TopicDiagnostic("scan", updater, du.FrequencyStatusParam({"min": 0}),
                               du.TimeStampStatusParam())
    image_pub = Recorder()
    diagnosed = du.DiagnosedPublisher(image_pub, updater, du.FrequencyStatusParam({"min": 2, "max": 4}),
                                      du.TimeStampStatusParam(0, 0.2))
    updater.add(du.Heartbeat())
    for second in range(6):
        for i in range(10 if second != 3 else 20):
            advance(0.1 if second != 3 else 0.05)
            freq.tick()
            if i % 2:
                headerless.tick()
            topic.tick(CLOCK[0] - rospy.Duration.from_sec(0.25 * second))
            stamps.tick((CLOCK[0] - rospy.Duration.from_sec(0.3 * second)).to_sec())
            if i % 3 == 0:
                msg = PointStamped()
                msg.header.stamp = CLOCK[0] - rospy.Duration.from_sec(0.1)
                diagnosed.publish(msg)
        if second == 4:
            stamps.tick(0.0)  # a zero stamp
            topic.tick(CLOCK[0] + rospy.Duration.from_sec(2))  # from the future
        if second == 2:
            updater.setHardwareID("hw-42")
        updater.force_update()
    updater.update()  # within the period: no output
    advance(1.5)
    updater.update()  # past it: output
    assert updater.removeByName("plain function") and not updater.removeByName("nothing")
    updater.broadcast(2, "shutting down")
    for array in published.sent:
        print(json.dumps(dump(array), sort_keys=True))
    print(json.dumps({"image_pub": len(image_pub.sent)}))


if __name__ == "__main__":
    main()
