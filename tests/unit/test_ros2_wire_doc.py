"""docs/ros2.md's wire excerpts are the captured datagrams, laid out by
scripts/ros2_wire_doc.py: the page and the captures must agree."""

from __future__ import annotations

import importlib.util
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_the_page_shows_the_captures():
    spec = importlib.util.spec_from_file_location("ros2_wire_doc",
                                                  REPO / "scripts" / "ros2_wire_doc.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    doc = (REPO / "docs" / "ros2.md").read_text()
    assert module.render(doc) == doc, "run: .venv/bin/python scripts/ros2_wire_doc.py --write"
    names = {m.group("name") for m in module.BLOCK.finditer(doc)}
    assert names == set(module.excerpts())
