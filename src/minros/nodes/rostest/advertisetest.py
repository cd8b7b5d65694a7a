"""advertisetest: each topic and service a test lists is advertised in time (or, ``negative``,
is not), with the type it names.

``~topics`` and ``~services`` (<rosparam> lists): ``name``, ``timeout`` (wall seconds, 10),
``type``, ``negative``.
"""

from __future__ import annotations

import sys
import time
import unittest
from typing import Callable, Dict, List, Optional

import minros
from minros.nodes.rostest._common import entries, run, wait_for_clock

POLL = 0.05  # seconds between two looks at the master's registrations (it sends no events)


class AdvertiseTest(unittest.TestCase):
    def setUp(self) -> None:
        self.topics = entries(self, "~topics", {"timeout": 10, "type": None, "negative": False})
        self.services = entries(self, "~services",
                                {"timeout": 10, "type": None, "negative": False})
        self.assertTrue(self.topics or self.services,
                        f"no topic or service is given in {minros.resolve_name('~topics')} "
                        f"or {minros.resolve_name('~services')}")
        wait_for_clock(self)
        self.started = time.monotonic()

    def _check(self, what: str, wanted: List[dict], advertised: Callable[[], Dict[str, str]],
               type_of: Callable[[str, Dict[str, str]], Optional[str]]) -> None:
        if not wanted:
            return
        by_name = {str(w["name"]): w for w in wanted}
        left = set(by_name)
        limit = max(float(w["timeout"]) for w in wanted)
        while left and not minros.is_shutdown():
            elapsed = time.monotonic() - self.started
            if elapsed > limit:
                break
            found = advertised()
            for name in sorted(left & set(found)):
                left.discard(name)
                entry = by_name[name]
                self.assertFalse(entry["negative"], f"{what} [{name}] is advertised")
                self.assertLess(elapsed, float(entry["timeout"]),
                                f"{what} [{name}] was advertised only after its timeout "
                                f"[{entry['timeout']}] s")
                if entry["type"] is not None:
                    actual = type_of(name, found)
                    self.assertEqual(actual, entry["type"],
                                     f"{what} type of [{name}] is [{actual}]")
            time.sleep(POLL)
        for name in sorted(left):
            self.assertTrue(by_name[name]["negative"], f"{what} [{name}] is not advertised")

    def test_advertise_topics(self) -> None:
        """Test topics are advertised"""
        self._check("Topic", self.topics,
                    lambda: dict(minros.get_published_topics()),
                    lambda name, found: found.get(name))

    def test_advertise_services(self) -> None:
        """Test services are advertised"""
        from minros.tools.master import Master
        from minros.tools.services import probe_service

        master = Master(minros.get_name())

        def service_type(name: str, found: Dict[str, str]) -> Optional[str]:
            try:  # as rosservice learns it: a probe of the server's connection header
                return probe_service(found[name], name, minros.get_name()).get("type")
            except Exception as exc:  # noqa: BLE001 - the server went away or answers garbage
                return f"<no answer: {exc}>"

        def advertised() -> Dict[str, str]:
            found = {}
            for name, _nodes in master.system_state()[2]:
                try:
                    found[name] = master.lookupService(name)
                except Exception:  # noqa: BLE001 - unregistered in between: not advertised
                    continue
            return found

        self._check("Service", self.services, advertised, service_type)


def main(argv: Optional[List[str]] = None) -> int:
    return run("advertisetest", AdvertiseTest, argv)


if __name__ == "__main__":
    sys.exit(main())
