"""The start-up hook's finder and minros's own crawl ROS_PACKAGE_PATH only for an import they
serve (``pkg.msg``, ``pkg.srv``, ``pkg.cfg``), not for every module some import fails to find."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

import _minros_import_hook
from minros import packages
from minros.msgs import importer


def _package(root: Path, name: str) -> None:
    (root / name / "msg").mkdir(parents=True)
    (root / name / "package.xml").write_text(f"<package format='2'><name>{name}</name></package>\n")
    (root / name / "msg" / "Num.msg").write_text("int64 num\n")


@pytest.fixture
def crawls(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> list:
    """ROS_PACKAGE_PATH = tmp_path/ws (one package at its top, one deep); the folders crawled."""
    ws = tmp_path / "ws"
    _package(ws, "top_lazy_msgs")
    _package(ws / "repo" / "group", "deep_lazy_msgs")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ws))
    walked: list = []
    walk = packages._walk
    monkeypatch.setattr(packages, "_walk", lambda root, found: (walked.append(root), walk(root, found)))
    monkeypatch.setattr(packages, "_cache", {})
    yield walked
    for name in list(sys.modules):
        if name.partition(".")[0] in ("top_lazy_msgs", "deep_lazy_msgs"):
            del sys.modules[name]


@pytest.mark.parametrize("finder", [_minros_import_hook.EnvironmentFinder(), importer.MsgImportFinder()],
                         ids=["start-up hook", "minros finder"])
def test_a_miss_does_not_crawl(crawls: list, finder) -> None:
    for name in ("org", "apport_python_hook", "sitecustomize", "numpy.core._x", "a.b.c", "deep_lazy_msgs"):
        assert finder.find_spec(name) is None, name
    assert crawls == []


def test_a_served_import_crawls_and_imports(crawls: list) -> None:
    # a package at the top of an entry is one stat away, so bare ``import top_lazy_msgs`` works
    assert _minros_import_hook.worth_a_look("top_lazy_msgs", str(packages.ros_package_path()[0]))
    finder = importer.MsgImportFinder()
    sys.meta_path.append(finder)
    try:
        deep = importlib.import_module("deep_lazy_msgs.msg")  # its parent is asked first
        assert crawls
        assert deep.Num._type == "deep_lazy_msgs/Num"
        assert importlib.import_module("top_lazy_msgs").__spec__.loader is not None
    finally:
        sys.meta_path.remove(finder)
