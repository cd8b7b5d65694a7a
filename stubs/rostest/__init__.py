"""Stand-in for rostest's Python API: what test nodes call (minros.tools.testing, the master
client of minros.tools.master)."""

from __future__ import annotations

import sys
from typing import Any, Sequence

from minros.tools.master import Master
from minros.tools.testing import XML_OUTPUT_FLAG  # noqa: F401


def rosrun(package: str, test_name: str, test: Any, sysargs: Sequence[str] | None = None) -> None:
    """Run a unittest TestCase as a rostest node: results where rostest asked for them
    (``--gtest_output``) or on the console (``--text``); the node is shut down at the end and
    the process exits 1 when a test failed."""
    from minros.node import signal_shutdown
    from minros.tools.testing import run_suite

    result = run_suite(package, test_name, test, sysargs)
    signal_shutdown("test complete")
    if not result.wasSuccessful():
        sys.exit(1)


run = rosrun


def unitrun(package: str, test_name: str, test: Any, sysargs: Sequence[str] | None = None,
            coverage_packages: Any = None) -> None:
    """Run a unittest TestCase without a ROS graph (rosunit)."""
    from rosunit import unitrun as _unitrun

    _unitrun(package, test_name, test, sysargs, coverage_packages)


def get_master() -> Master:
    """The master client test code queries the graph with."""
    return Master("/rostest")


def is_subscriber(topic: str, subscriber_id: str) -> bool:
    """Whether ``subscriber_id`` subscribes to ``topic``."""
    _pubs, subs, _srvs = get_master().system_state()
    return any(name == topic and subscriber_id in nodes for name, nodes in subs)


def is_publisher(topic: str, publisher_id: str) -> bool:
    """Whether ``publisher_id`` publishes ``topic``."""
    pubs, _subs, _srvs = get_master().system_state()
    return any(name == topic and publisher_id in nodes for name, nodes in pubs)
