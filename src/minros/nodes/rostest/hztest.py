"""hztest: a topic arrives at the rate a test expects.

Parameters (private): ``topic``, ``hz`` (0: the topic must stay silent), ``hzerror`` (the
allowed deviation, needed unless hz is 0), ``test_duration`` (seconds measured),
``wait_time`` (wall seconds to wait for the first message, 20), ``check_intervals`` (also
bound each gap between two messages), ``wall_clock`` (measure wall time, not ROS time).
The rate is (messages - 1) / (last - first) over the measuring window, which starts once
the first message came.
"""

from __future__ import annotations

import sys
import threading
import time
import unittest
from typing import Any, List, Optional

import minros
from minros.nodes.rostest._common import required, run


class HzTest(unittest.TestCase):
    def test_hz(self) -> None:
        topic = str(required(self, "~topic"))
        hz = float(required(self, "~hz"))
        duration = float(required(self, "~test_duration"))
        hzerror = float(required(self, "~hzerror")) if hz != 0.0 else 0.0
        wait_time = float(minros.get_param("~wait_time", 20.0))
        self.check_intervals = bool(minros.get_param("~check_intervals", False))
        self.wall_clock = bool(minros.get_param("~wall_clock", False))
        print(f"Hz: {hz}\nHz Error: {hzerror}\nTopic: {topic}\nTest Duration: {duration}")
        self.assertTrue(hz >= 0.0, "bad parameter (hz)")
        self.assertTrue(hzerror >= 0.0, "bad parameter (hzerror)")
        self.assertTrue(duration > 0.0, "bad parameter (test_duration)")
        self.assertTrue(topic, "bad parameter (topic)")
        low, high = (hz - hzerror, hz + hzerror) if hz else (0.0, 0.0)
        self.min_interval = 1.0 / high if high > 0 else 0.0
        self.max_interval = 1.0 / low if low > 0 else 0.0
        self.lock = threading.Lock()
        self.first = threading.Event()
        self.count = 0
        self.t0: Optional[float] = None
        self.tn: Optional[float] = None
        self.errors: List[str] = []

        sub = minros.Subscriber(topic, minros.AnyMsg, self.on_message)
        print("Waiting for messages")
        came = self.first.wait(wait_time)
        if hz > 0:
            self.assertTrue(came, f"no messages on {topic} within {wait_time:g} s")
        else:
            self.assertFalse(came, f"a message came on {topic}, which should stay silent")
        print("Starting rate measurement")
        if self.wall_clock:
            time.sleep(duration)  # the measuring window itself
        else:
            minros.sleep(duration)
        print("Done waiting, validating results")
        sub.unregister()
        with self.lock:
            count, t0, tn, errors = self.count, self.t0, self.tn, list(self.errors)
        if hz == 0:
            self.assertEqual(0, count, f"{count} messages on {topic}, which should stay silent")
            return
        self.assertTrue(count > 0, "no messages received")
        self.assertFalse(errors, "\n".join(errors))
        assert t0 is not None and tn is not None
        self.assertTrue(tn > t0, "only one message received")
        rate = (count - 1) / (tn - t0)
        self.assertTrue(rate >= low, f"average rate ({rate:.3f}Hz) exceeded minimum ({low:.3f}Hz)")
        self.assertTrue(rate <= high, f"average rate ({rate:.3f}Hz) exceeded maximum ({high:.3f}Hz)")

    def on_message(self, msg: Any) -> None:
        self.first.set()
        if self.wall_clock:
            now = time.time()
        else:
            stamp = minros.get_rostime()
            if stamp.is_zero():
                return  # sim time before the first /clock
            now = stamp.to_sec()
        with self.lock:
            last = self.tn
            if self.t0 is None or self.t0 > now:  # the first, or time went back (sim time)
                self.t0, self.count, last = now, 1, None
            else:
                self.count += 1
            self.tn = now
            if self.check_intervals and last is not None:
                gap = now - last
                if gap < self.min_interval:
                    self.errors.append(f"min_interval exceeded: {gap} [actual] vs. "
                                       f"{self.min_interval} [min]")
                elif self.max_interval > 0.0 and gap > self.max_interval:
                    self.errors.append(f"max_interval exceeded: {gap} [actual] vs. "
                                       f"{self.max_interval} [max]")


def main(argv: Optional[List[str]] = None) -> int:
    return run("hztest", HzTest, argv)


if __name__ == "__main__":
    sys.exit(main())
