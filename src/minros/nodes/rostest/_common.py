"""What rostest's test nodes share: start the node, run the case, read typed parameters."""

from __future__ import annotations

import sys
import time
import unittest
from typing import Any, List, Optional

import minros


def run(name: str, case: type, argv: Optional[List[str]] = None) -> int:
    """Run the TestCase ``case`` as rostest's nodes run theirs (package ``rostest``)."""
    from minros.node import signal_shutdown
    from minros.tools.testing import run_suite

    args = list(sys.argv if argv is None else argv)
    minros.init_node(name, argv=args)
    try:
        result = run_suite("rostest", name, case, args)
    finally:
        signal_shutdown("test complete")
    return 0 if result.wasSuccessful() else 1


def required(case: unittest.TestCase, name: str) -> Any:
    """A private parameter the test cannot run without; a clear failure naming it otherwise."""
    try:
        return minros.get_param(name)
    except KeyError:
        case.fail(f"{type(case).__name__.lower()} not initialized properly: parameter "
                  f"[{minros.resolve_name(name)}] is not set (give it in the <test> as "
                  f'<param name="{name.lstrip("~")}" value="..."/>)')


def wait_for_clock(case: unittest.TestCase, limit: float = 10.0) -> None:
    """With /use_sim_time, wait (wall clock) until /clock has given a time."""
    if not minros.get_param("/use_sim_time", False):
        return
    deadline = time.monotonic() + limit
    while not minros.is_shutdown() and minros.Time.now() == minros.Time(0):
        if time.monotonic() > deadline:
            case.fail(f"/use_sim_time is set and no /clock came within {limit:g} s")
        time.sleep(0.05)  # /clock's first message has no event to wait on from here


def entries(case: unittest.TestCase, key: str, defaults: dict) -> List[dict]:
    """The ``~topics``/``~services`` list of a <rosparam>: each a dict with ``name``."""
    found = []
    for entry in minros.get_param(key, []) or []:
        if not isinstance(entry, dict) or "name" not in entry:
            case.fail(f"each entry of {minros.resolve_name(key)} needs a 'name' field: {entry!r}")
        found.append({**defaults, **entry})
    return found
