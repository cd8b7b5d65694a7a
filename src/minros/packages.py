"""ROS package discovery: the packages on ROS_PACKAGE_PATH and the ones minros ships.

A package is a folder holding a ``package.xml``; its name is the manifest's ``<name>``
(as rospack reads it), not the folder's. Discovery walks each ROS_PACKAGE_PATH entry in
order, does not descend into a package, skips folders holding ``CATKIN_IGNORE`` and hidden
folders, and the first package found under a name wins. minros's bundled packages (message
definitions, turtlesim, rospy_tutorials, ...) come last, so a workspace can override them.
"""

from __future__ import annotations

import os
import re
import threading
from pathlib import Path
from typing import Dict, List, Optional

#: Folders under which minros keeps the packages it ships, in lookup order.
BUILTIN_SHARE_DIRS: List[Path] = [Path(__file__).resolve().parent / "msgs" / "share"]

_NAME_RE = re.compile(rb"<name>\s*([^<\s]+)\s*</name>")
_cache: Dict[str, Dict[str, Path]] = {}
_cache_lock = threading.Lock()


def ros_package_path() -> List[Path]:
    """The entries of ROS_PACKAGE_PATH, in order, empty entries dropped."""
    value = os.environ.get("ROS_PACKAGE_PATH", "")
    return [Path(p) for p in value.split(os.pathsep) if p.strip()]


def manifest_name(package_dir: Path) -> Optional[str]:
    """The ``<name>`` declared in ``package_dir/package.xml``, or None if unreadable."""
    try:
        head = (package_dir / "package.xml").read_bytes()[:65536]
    except OSError:
        return None
    match = _NAME_RE.search(head)
    return match.group(1).decode("utf-8", "replace") if match else None


def _walk(root: Path, found: Dict[str, Path]) -> None:
    """Add every package below ``root`` to ``found`` (first one under a name wins)."""
    try:
        if (root / "package.xml").is_file():
            name = manifest_name(root) or root.name
            found.setdefault(name, root)
            return
        if (root / "CATKIN_IGNORE").exists():
            return
        children = sorted(os.scandir(root), key=lambda e: e.name)
    except OSError:
        return
    for entry in children:
        if entry.name.startswith(".") or not entry.is_dir():
            continue
        _walk(Path(entry.path), found)


def _search_roots() -> List[Path]:
    return ros_package_path() + list(BUILTIN_SHARE_DIRS)


def list_packages(refresh: bool = False) -> Dict[str, Path]:
    """All packages visible now: ``{name: folder}``, ROS_PACKAGE_PATH first, then built-ins."""
    roots = _search_roots()
    key = os.pathsep.join(str(r) for r in roots)
    with _cache_lock:
        if not refresh and key in _cache:
            return dict(_cache[key])
    found: Dict[str, Path] = {}
    for root in roots:
        _walk(root, found)
    with _cache_lock:
        _cache[key] = found
    return dict(found)


def find_package(name: str) -> Optional[Path]:
    """The folder of package ``name``, or None. Re-scans once on a miss (new packages)."""
    path = list_packages().get(name)
    if path is None:
        path = list_packages(refresh=True).get(name)
    return path


def is_builtin(package_dir: Path) -> bool:
    """Whether ``package_dir`` is one of the packages minros ships."""
    resolved = Path(package_dir).resolve()
    return any(root in resolved.parents for root in BUILTIN_SHARE_DIRS)
