"""ROS package discovery: the packages on ROS_PACKAGE_PATH and the ones minros ships.

A package is a folder holding a ``package.xml``; its name is the manifest's ``<name>``
(as rospack reads it), not the folder's. Discovery walks each ROS_PACKAGE_PATH entry in
order, does not descend into a package, skips folders holding ``CATKIN_IGNORE`` and hidden
folders, and the first package found under a name wins. minros's bundled packages come last,
so a workspace can override them: message definitions, turtlesim, rospy_tutorials, ..., and a
``package.xml`` (with Debian's ROS version) for each ROS package whose Python API, nodes or
tools minros provides (rospy, roslaunch, rosbag, ...), so ``rosversion``, ``rospack find`` and
``roslib.load_manifest`` know them as on a real install.
"""

from __future__ import annotations

import os
import re
import threading
from pathlib import Path
from typing import Any, Dict, List, Optional

#: Folders under which minros keeps the packages it ships, in lookup order.
BUILTIN_SHARE_DIRS: List[Path] = [Path(__file__).resolve().parent / "msgs" / "share"]

_NAME_RE = re.compile(rb"<name>\s*([^<\s]+)\s*</name>")
_VERSION_RE = re.compile(rb"<version(?:\s[^>]*)?>\s*([^<\s]+)\s*</version>")
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


def manifest_version(package_dir: Path) -> Optional[str]:
    """The ``<version>`` declared in ``package_dir/package.xml``, or None (rosversion's
    "<unversioned>")."""
    try:
        head = (package_dir / "package.xml").read_bytes()[:65536]
    except OSError:
        return None
    match = _VERSION_RE.search(head)
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


# ---------------------------------------------------------------------------------------------
# roslib's package API on rospkg (manifests, dependencies, the rosbuild python path)

def rospack() -> Any:
    """A ``rospkg.RosPack`` over the same roots minros searches (ROS_PACKAGE_PATH, then the
    bundled packages): rospkg reads manifests and dependency lists as ROS's tools do."""
    import rospkg

    return rospkg.RosPack(ros_paths=[str(p) for p in _search_roots()])


_bootstrapped: List[str] = []


def load_manifest(package_name: str) -> List[str]:
    """roslib.load_manifest: check that ``package_name`` exists (``rospkg.ResourceNotFound``
    naming the search path when it does not) and, for a rosbuild package (``manifest.xml``),
    return the folders to put on sys.path (its and its dependencies' ``src``/``lib`` or python
    exports), as catkin-era ROS does. A catkin package needs none."""
    if package_name in _bootstrapped:
        return []
    pack = rospack()
    manifest = pack.get_manifest(package_name)
    if manifest.is_catkin:
        _bootstrapped.append(package_name)
        return []
    paths: List[str] = []
    for name in pack.get_depends(package_name, implicit=True) + [package_name]:
        folder = pack.get_path(name)
        exports = pack.get_manifest(name).get_export("python", "path")
        if exports:
            paths += [e.replace("${prefix}", folder) for x in exports for e in x.split(":")]
        else:
            paths += [d for d in (os.path.join(folder, "src"), os.path.join(folder, "lib"))
                      if os.path.isdir(d)]
        _bootstrapped.append(name)
    return paths


def find_resource(package: str, resource_name: str, filter_fn: Any = None) -> List[str]:
    """Files called ``resource_name`` below package ``package`` (roslib.packages.find_resource),
    optionally kept only where ``filter_fn(path)`` is true; none for a missing package."""
    folder = find_package(package)
    if folder is None:
        return []
    found = []
    for dirpath, dirnames, filenames in os.walk(folder, followlinks=True):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
        if resource_name in filenames:
            path = os.path.join(dirpath, resource_name)
            if filter_fn is None or filter_fn(path):
                found.append(path)
    return found
