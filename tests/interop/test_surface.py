"""scripts/surface.py against Debian's installed ROS: the report is written and minros's share
of Debian's Python surface does not fall below the floor (raise the floors as modules land;
the target is every module but the exclusions importable and >= 85% of public names)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from support import REPO, require_reference

pytestmark = pytest.mark.interop

#: today's figures (docs/surface.md): importable modules and public names present
FLOOR_MODULES = 307
FLOOR_NAMES = 3310


def test_surface_report_and_floor(tmp_path: Path) -> None:
    require_reference()
    report, figures = tmp_path / "surface.md", tmp_path / "surface.json"
    run = subprocess.run([sys.executable, str(REPO / "scripts" / "surface.py"),
                          "--output", str(report), "--json", str(figures),
                          "--minros-python", sys.executable],
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    text = report.read_text()
    assert "| Debian package | modules | importable in minros |" in text
    assert "## Excluded modules" in text and "| python3-rospy |" in text
    data = json.loads(figures.read_text())
    total = data["figures"]["total"]
    assert total["modules"] >= 250  # Debian's desktop-full surface was listed, not a fragment
    assert total["importable"] >= FLOOR_MODULES, run.stdout
    assert total["present"] >= FLOOR_NAMES, run.stdout
    # the message packages minros bundles are importable with all their classes
    # and so are the tools' Python APIs and the libraries whose every name minros has
    for package in ("python3-map-msgs", "python3-move-base-msgs", "python3-std-msgs",
                    "python3-rostopic", "python3-rosnode", "python3-rosparam", "python3-rosmsg",
                    "python3-rosservice", "python3-catkin", "python3-camera-calibration-parsers",
                    "python3-python-qt-binding", "python3-tf2-ros", "python3-actionlib",
                    "python3-interactive-markers", "python3-cv-bridge", "joint-state-publisher"):
        entry = data["figures"]["packages"][package]
        assert entry["importable"] == entry["modules"] and entry["present"] == entry["names"]
    assert data["modules"]["rosmake"]["excluded"]
    assert data["modules"]["joint_state_publisher_gui"]["excluded"]
