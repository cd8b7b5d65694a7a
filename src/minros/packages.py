"""ROS package discovery: the packages on ROS_PACKAGE_PATH and the ones minros ships.

A package is a folder holding a ``package.xml``; its name is the manifest's ``<name>``
(as rospack reads it), not the folder's (a rosbuild package, with a ``manifest.xml``, is named
by its folder). Discovery walks each ROS_PACKAGE_PATH entry in
order, does not descend into a package, skips folders holding ``CATKIN_IGNORE`` and hidden
folders, and the first package found under a name wins. minros's bundled packages come last,
so a workspace can override them: message definitions, turtlesim, rospy_tutorials, ..., and a
``package.xml`` (with Debian's ROS version) for each ROS package whose Python API, nodes or
tools minros provides (rospy, roslaunch, rosbag, ...), so ``rosversion``, ``rospack find`` and
``roslib.load_manifest`` know them as on a real install.

The packages a first one hides stay known (:func:`package_folders`): an overlay package that
lacks a message, a service or a whole ``msg/``/``srv/`` folder does not hide its underlay's
(the message system looks in every folder of a name, in order), as ROS falls back to the
underlay for the messages an overlay does not have.
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
_cache: Dict[str, Dict[str, List[Path]]] = {}
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


def _walk(root: Path, found: Dict[str, List[Path]]) -> None:
    """Add every package below ``root`` to ``found`` (each name's folders in search order)."""
    try:
        if (root / "package.xml").is_file():
            name = manifest_name(root) or root.name
            found.setdefault(name, []).append(root)
            return
        if (root / "manifest.xml").is_file():  # a rosbuild package: named by its folder
            found.setdefault(root.name, []).append(root)
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


def _all_packages(refresh: bool = False) -> Dict[str, List[Path]]:
    roots = _search_roots()
    key = os.pathsep.join(str(r) for r in roots)
    with _cache_lock:
        if not refresh and key in _cache:
            return _cache[key]
    found: Dict[str, List[Path]] = {}
    for root in roots:
        _walk(root, found)
    with _cache_lock:
        _cache[key] = found
    return found


def list_packages(refresh: bool = False) -> Dict[str, Path]:
    """All packages visible now: ``{name: folder}``, ROS_PACKAGE_PATH first, then built-ins."""
    return {name: folders[0] for name, folders in _all_packages(refresh).items()}


def find_package(name: str) -> Optional[Path]:
    """The folder of package ``name``, or None. Re-scans once on a miss (new packages)."""
    folders = package_folders(name)
    return folders[0] if folders else None


def known_package_folders(name: str) -> List[Path]:
    """:func:`package_folders` among the packages already discovered (no re-scan on a miss:
    for the import hook, asked about every module nothing else found)."""
    return list(_all_packages().get(name) or ())


def package_folders(name: str) -> List[Path]:
    """Every folder of a package named ``name``, in search order (the first is the package;
    the others are the underlays it hides). Re-scans once on a miss."""
    folders = _all_packages().get(name)
    if folders is None:
        folders = _all_packages(refresh=True).get(name)
    return list(folders or ())


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


# ---------------------------------------------------------------------------------------------
# roslib.packages' errors and lookups, roslib.manifest and roslib.resources (rosbuild-era API
# that catkin-era code and ROS's tests still call)

MANIFEST_FILE = "manifest.xml"
PACKAGE_FILE = "package.xml"


class ROSPkgException(Exception):
    """Base of roslib.packages' errors."""


class InvalidROSPkgException(ROSPkgException):
    """A package is missing or broken."""


class MultipleNodesException(ROSPkgException):
    """Several programs of one name in a package."""


def get_pkg_dir(package: str, required: bool = True) -> Optional[str]:
    """The folder of ``package``; InvalidROSPkgException (``required``) or None when missing,
    naming the search path as roslib does."""
    folder = find_package(package)
    if folder is None:
        if required:
            raise InvalidROSPkgException(
                f"Cannot locate installation of package {package}: [rospack] Error: package "
                f"'{package}' not found. ROS_ROOT[{os.environ.get('ROS_ROOT')}] "
                f"ROS_PACKAGE_PATH[{os.environ.get('ROS_PACKAGE_PATH', '')}]")
        return None
    return str(folder)


def resource_file(package: str, subdir: str, resource_name: str) -> str:
    """``<package>/<subdir>/<resource_name>``, whether or not the file exists."""
    return os.path.join(get_pkg_dir(package) or "", subdir, resource_name)


def get_dir_pkg(d: str) -> tuple:
    """``(package folder, package name)`` of the package folder ``d`` is in, or
    ``(None, None)`` (roslib.packages.get_dir_pkg)."""
    d = os.path.abspath(d)
    while True:
        if os.path.isfile(os.path.join(d, PACKAGE_FILE)) or os.path.isfile(os.path.join(d, MANIFEST_FILE)):
            return d, manifest_name(Path(d)) or os.path.basename(d)
        parent = os.path.dirname(d)
        if parent == d:
            return None, None
        d = parent


def manifest_file(package: str, required: bool = True) -> Optional[str]:
    """The ``manifest.xml`` of a rosbuild package (a catkin package has none: with
    ``required`` that is InvalidROSPkgException, as roslib.manifest says)."""
    folder = get_pkg_dir(package, required)
    if folder is None:
        return None
    path = os.path.join(folder, MANIFEST_FILE)
    if not os.path.isfile(path) and required:
        raise InvalidROSPkgException(
            f"\nPackage '{folder}' is improperly configured: no manifest file is present.\n")
    return path


class Depend:
    """A manifest's ``<depend package="..."/>`` as roslib.manifest names it."""

    __slots__ = ("package",)

    def __init__(self, package: str) -> None:
        self.package = package

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Depend) and other.package == self.package

    __hash__ = None  # type: ignore[assignment]

    def __str__(self) -> str:
        return self.package

    def __repr__(self) -> str:
        return self.package

    def xml(self) -> str:
        return f'<depend package="{self.package}" />'


def _roslib_depends(manifest: Any) -> Any:
    manifest.depends = [Depend(d.name) for d in manifest.depends]
    return manifest


def parse_manifest_file(path: str) -> Any:
    """A ``manifest.xml`` (or ``package.xml``) parsed by rospkg, its dependencies as
    roslib's :class:`Depend` (``.package``)."""
    import rospkg.manifest

    return _roslib_depends(rospkg.manifest.parse_manifest_file(os.path.dirname(path) or ".",
                                                               os.path.basename(path)))


def parse_manifest_text(text: str, filename: str = "string") -> Any:
    """A ``manifest.xml`` given as text, parsed as :func:`parse_manifest_file` does."""
    import rospkg.manifest

    return _roslib_depends(rospkg.manifest.parse_manifest(MANIFEST_FILE, text, filename))


def list_package_resources_by_dir(package_dir: str, include_depends: bool, subdir: str,
                                  rfilter: Any = os.path.isfile) -> List[str]:
    """Names of the entries of ``<package_dir>/<subdir>`` that ``rfilter`` accepts; with
    ``include_depends``, the dependencies' too, as ``pkg/name``."""
    folder = os.path.join(package_dir, subdir)
    found = sorted(name for name in (os.listdir(folder) if os.path.isdir(folder) else ())
                   if rfilter(os.path.join(folder, name)))
    if include_depends:
        name = manifest_name(Path(package_dir)) or os.path.basename(package_dir)
        for dep in rospack().get_depends(name, implicit=True):
            dep_dir = get_pkg_dir(dep, required=False)
            if dep_dir:
                found += [f"{dep}/{r}" for r in
                          list_package_resources_by_dir(dep_dir, False, subdir, rfilter)]
    return found


def list_package_resources(package: str, include_depends: bool, subdir: str,
                           rfilter: Any = os.path.isfile) -> List[str]:
    """:func:`list_package_resources_by_dir` for package ``package`` (none if it is missing)."""
    package_dir = get_pkg_dir(package, required=False)
    if package_dir is None:
        return []
    return list_package_resources_by_dir(package_dir, include_depends, subdir, rfilter)


# ---------------------------------------------------------------------------------------------
# rospack's and rosstack's dependency queries (roslib.rospack), answered by rospkg in-process

class ROSLibException(Exception):
    """Base of roslib's errors (roslib.exceptions)."""


def manifest_depends(name: str) -> List[str]:
    """The packages package ``name`` declares it depends on (every kind of dependency, as
    rospack lists them) that can be found. Conditions are not evaluated: what they choose
    between (python-setuptools or python3-setuptools) are system packages, never found."""
    folder = find_package(name)
    if folder is None:
        raise ROSLibException(f"[rospack] Error: package '{name}' not found")
    declared: List[str] = []
    if (folder / PACKAGE_FILE).is_file():
        from catkin_pkg.package import parse_package

        package = parse_package(str(folder / PACKAGE_FILE))
        for dep in (package.buildtool_depends + package.build_depends + package.run_depends
                    + package.test_depends):
            declared.append(dep.name)
    elif (folder / MANIFEST_FILE).is_file():
        declared = [d.package for d in parse_manifest_file(str(folder / MANIFEST_FILE)).depends]
    known = list_packages()
    return [d for d in dict.fromkeys(declared) if d in known and d != name]


def _depends(name: str, direct: bool) -> List[str]:
    found: List[str] = []
    todo = [name]
    while todo:
        for dep in manifest_depends(todo.pop(0)):
            if dep not in found:
                found.append(dep)
                if not direct:
                    todo.append(dep)
    return found


def dependency_query(name: str, reverse: bool = False, direct: bool = False) -> List[str]:
    """What package ``name`` depends on, or with ``reverse`` what depends on it; ``direct``
    for first-order only (rospack deps/deps1/depends-on/depends-on1). Declared dependencies
    that are not installed are passed over. ROSLibException with rospack's text for an
    unknown package."""
    if find_package(name) is None:
        raise ROSLibException(f"[rospack] Error: package '{name}' not found")
    if not reverse:
        return _depends(name, direct)
    found = []
    for other in sorted(list_packages()):
        try:
            if other != name and name in _depends(other, direct):
                found.append(other)
        except Exception:  # noqa: BLE001 - an unreadable manifest depends on nothing
            continue
    return found


def reachable_packages(name: str) -> List[str]:
    """Every package ``name`` depends on, directly or not, that can be found: the packages
    whose messages its own may embed ([] for a package that is not installed)."""
    try:
        return _depends(name, direct=False)
    except ROSLibException:
        return []


def plugins(package: str, attrib: str = "plugin") -> List[tuple]:
    """``(package, value)`` for each package that depends on ``package`` and exports
    ``<package attrib="value"/>`` (rospack plugins --attrib=ATTRIB PACKAGE)."""
    pack = rospack()
    found = []
    for name in [package] + dependency_query(package, reverse=True, direct=True):
        for value in pack.get_manifest(name).get_export(package, attrib):
            found.append((name, value))
    return found
