"""The quick tier (``pytest tests/unit -m "not slow and not fuzz"``) runs in the pytest process:
tests/conftest.py refuses every way a process starts while such a test sets up, runs and tears
down, and fails the test that tries (the README and docs/architecture.md give its cost)."""

from __future__ import annotations

import os
import subprocess

import pytest

import conftest


def _refused(owner, name: str) -> bool:
    return getattr(owner, name).__qualname__.startswith("_NoProcesses._refuse")


def test_a_quick_test_runs_with_every_way_to_start_a_process_refused():
    targets = conftest._NoProcesses().targets
    assert (subprocess.Popen, "_execute_child") in targets and (os, "fork") in targets
    assert [(owner, name) for owner, name in targets if not _refused(owner, name)] == []


def test_a_refused_start_raises_and_names_the_program():
    with conftest._NoProcesses() as guard:
        with pytest.raises(conftest.ProcessStartedError, match="true"):
            subprocess.run(["true", "--now"])
    assert guard.started == ["_execute_child(['true', '--now'])"]
    assert _refused(subprocess.Popen, "_execute_child")  # the test's own guard is back


@pytest.mark.slow
def test_a_slow_test_starts_processes_as_it_likes():
    assert not any(_refused(owner, name) for owner, name in conftest._NoProcesses().targets)
    assert subprocess.run(["true"]).returncode == 0
