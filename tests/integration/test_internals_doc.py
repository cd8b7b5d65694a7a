"""docs/internals.md shows real traces: scripts/internals_traces.py reruns its scenarios and
the page must agree with this run (ports, pids, times and counts aside)."""

from __future__ import annotations

import importlib.util
import subprocess

from support import PYTHON, REPO

SCRIPT = REPO / "scripts" / "internals_traces.py"


def _script():
    spec = importlib.util.spec_from_file_location("internals_traces", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_comparison_ignores_only_what_changes_between_runs():
    normalize = _script().normalize
    one = (' [4]   +1.289                  <- 1, "ready on localhost:42171", ["TCPROS", "localhost", '
           '42171]\n       message 1: length prefix 11000000 = 17 bytes, received 0.23 ms later\n'
           '                               (and 3 more times, the last at +2.653)')
    other = one.replace("42171", "39001").replace("+1.289", "+12.007").replace("0.23", "1.50")
    other = other.replace("(and 3 more times", "(and 1 more time")
    assert normalize(one) == normalize(other)
    assert normalize(one) != normalize(one.replace("11000000 = 17", "12000000 = 18"))
    assert normalize(one) != normalize(one.replace("[4]", "[3]"))


def test_the_page_agrees_with_a_fresh_run():
    done = subprocess.run([PYTHON, str(SCRIPT), "--check"], capture_output=True, text=True,
                          timeout=240)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "7 excerpts agree with this run" in done.stdout
