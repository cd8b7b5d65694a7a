"""publishtest: messages come on each topic a test lists (or, ``negative``, none do).

``~topics`` (a <rosparam> list): ``name``, ``timeout`` (ROS seconds, 10), ``negative``
(the topic must stay silent until its timeout).
"""

from __future__ import annotations

import sys
import threading
import unittest
from typing import Any, List, Optional

import minros
from minros.nodes.rostest._common import entries, run, wait_for_clock


class _Watch:
    def __init__(self, topic: dict) -> None:
        self.name = str(topic["name"])
        self.negative = bool(topic["negative"])
        self.deadline = minros.Time.now() + minros.Duration(float(topic["timeout"]))
        self.came = threading.Event()
        self.sub = minros.Subscriber(self.name, minros.AnyMsg, self._on_message)

    def _on_message(self, msg: Any) -> None:
        self.came.set()

    def verdict(self) -> Optional[bool]:
        """Passed, failed, or None while undecided."""
        if self.came.is_set():
            return not self.negative
        if minros.Time.now() > self.deadline:
            return self.negative
        return None


class PublishTest(unittest.TestCase):
    def test_publish(self) -> None:
        """Test topics are published and messages come"""
        topics = entries(self, "~topics", {"timeout": 10, "negative": False})
        self.assertTrue(topics, f"no topic is given in {minros.resolve_name('~topics')}")
        wait_for_clock(self)
        watches = []
        for topic in topics:
            print(f"Waiting [{topic['name']}] for [{topic['timeout']}] seconds with negative "
                  f"[{topic['negative']}]")
            watches.append(_Watch(topic))
        undecided = list(watches)
        while undecided and not minros.is_shutdown():
            for watch in list(undecided):
                verdict = watch.verdict()
                if verdict is None:
                    continue
                undecided.remove(watch)
                if watch.negative:
                    self.assertTrue(verdict, f"Topic [{watch.name}] is published")
                else:
                    self.assertTrue(verdict, f"Topic [{watch.name}] is not published")
            minros.sleep(0.01)


def main(argv: Optional[List[str]] = None) -> int:
    return run("publishtest", PublishTest, argv)


if __name__ == "__main__":
    sys.exit(main())
