"""rosbuild's manifests and stacks, as roslib.manifestlib, roslib.stack_manifest and
roslib.stacks expose them, over minros's package lookup (ROS_PACKAGE_PATH, then the packages
minros ships; rospkg reads the stacks there as ROS's tools do).

A rosbuild ``manifest.xml`` (``<package>``) or ``stack.xml`` (``<stack>``) is parsed with the
standard library's DOM into a :class:`Manifest`: the ``check_*`` functions are the field
readers (each returns a function of the top element and the file name), ``parse`` fills a
manifest object with them.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple
from xml.dom import minidom

from minros import packages

REQUIRED = ["author", "license"]
ALLOWXHTML = ["description"]
OPTIONAL = ["logo", "url", "brief", "description", "status", "notes", "depend", "rosdep",
            "export", "review", "versioncontrol", "platform", "version", "rosbuild2",
            "catkin"]
VALID = REQUIRED + OPTIONAL
STACK_FILE = "stack.xml"
ROS_STACK = "ros"  # the stack ROS itself was

Check = Callable[[Any, str], Any]


class ManifestException(packages.ROSLibException):
    """A manifest is not valid XML or lacks a required field."""


class ROSStackException(Exception):
    pass


class InvalidROSStackException(ROSStackException):
    """No stack of that name is on the package path."""


# ---------------------------------------------------------------------------------------------
# the fields of a manifest

def _xml_attrs(attrs: Mapping[str, str]) -> str:
    return "".join(f' {k}="{v}"' for k, v in attrs.items())


class Export:
    """One element of ``<export>``: its tag, attributes and text."""

    def __init__(self, tag: str, attrs: Dict[str, str], str: str) -> None:  # noqa: A002 - roslib's
        self.tag = tag
        self.attrs = attrs
        self.str = str

    def get(self, attr: str) -> Optional[str]:
        return self.attrs.get(attr)

    def xml(self) -> str:
        if self.str:
            return f"<{self.tag}{_xml_attrs(self.attrs)}>{self.str}</{self.tag}>"
        return f"<{self.tag}{_xml_attrs(self.attrs)} />"


class Platform:
    """A ``<platform os= version= notes=>`` the package supports."""

    def __init__(self, os: str, version: str, notes: Optional[str] = None) -> None:  # noqa: A002
        if not os or not version:
            raise ValueError("os and version must be set")
        self.os, self.version, self.notes = os, version, notes

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Platform) and (self.os, self.version, self.notes) == \
            (other.os, other.version, other.notes)

    def __hash__(self) -> int:
        return hash((self.os, self.version))

    def __str__(self) -> str:
        return f"{self.os} {self.version}"

    def xml(self) -> str:
        notes = f' notes="{self.notes}"' if self.notes is not None else ""
        return f'<platform os="{self.os}" version="{self.version}"{notes}/>'


class Depend:
    """A package's ``<depend package=...>``."""

    def __init__(self, package: str) -> None:
        if not package:
            raise ValueError("bad 'package' attribute")
        self.package = package

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Depend) and other.package == self.package

    def __hash__(self) -> int:
        return hash(self.package)

    def __str__(self) -> str:
        return self.package

    __repr__ = __str__

    def xml(self) -> str:
        return f'<depend package="{self.package}" />'


class StackDepend:
    """A stack's ``<depend stack=...>``; ``annotation`` becomes an XML comment."""

    def __init__(self, stack: str, annotation: Optional[str] = None) -> None:
        if not stack:
            raise ValueError("bad 'stack' attribute")
        self.stack = stack
        self.annotation = annotation

    def __eq__(self, other: object) -> bool:
        return isinstance(other, StackDepend) and other.stack == self.stack

    def __hash__(self) -> int:
        return hash(self.stack)

    def __str__(self) -> str:
        return self.stack

    __repr__ = __str__

    def xml(self) -> str:
        comment = f" <!-- {self.annotation} -->" if self.annotation else ""
        return f'<depend stack="{self.stack}" />{comment}'


class ROSDep:
    """A ``<rosdep name=...>`` (a system dependency)."""

    def __init__(self, name: str) -> None:
        if not name:
            raise ValueError("bad 'name' attribute")
        self.name = name

    def xml(self) -> str:
        return f'<rosdep name="{self.name}" />'


class VersionControl:
    """The ``<versioncontrol type= url=>`` of a package or stack."""

    def __init__(self, type_: str, url: Optional[str]) -> None:
        self.type = type_
        self.url = url

    def xml(self) -> str:
        url = f' url="{self.url}"' if self.url else ""
        return f'<versioncontrol type="{self.type}"{url} />'


# ---------------------------------------------------------------------------------------------
# reading the fields from the DOM

def get_nodes_by_name(n: Any, name: str) -> List[Any]:
    """The child elements of ``n`` named ``name``."""
    return [c for c in n.childNodes if c.nodeType == c.ELEMENT_NODE and c.tagName == name]


def _text(nodes: Sequence[Any]) -> str:
    return "".join(n.data for n in nodes if n.nodeType == n.TEXT_NODE)


def _inner_xml(node: Any) -> str:
    return "".join(child.toxml() for child in node.childNodes)


def _fields(n: Any, name: str, allow_xhtml: bool, merge_multiple: bool, filename: str) -> str:
    found = get_nodes_by_name(n, name)
    if len(found) > 1 and not merge_multiple:
        raise ManifestException(f"Invalid manifest file [{filename}]: must have a single '{name}' element")
    texts = [(_inner_xml(f) if allow_xhtml else _text(f.childNodes)).strip() for f in found]
    return ", ".join(t for t in texts if t)


def check_optional(name: str, allowXHTML: bool = False, merge_multiple: bool = False) -> Check:  # noqa: N803
    """A reader of optional element ``name``: its text ('' when absent)."""
    def check(n: Any, filename: str) -> str:
        return _fields(n, name, allowXHTML, merge_multiple, filename)
    return check


def check_required(name: str, allowXHTML: bool = False, merge_multiple: bool = False) -> Check:  # noqa: N803
    """A reader of required element ``name``: ManifestException when it is missing."""
    def check(n: Any, filename: str) -> str:
        if not get_nodes_by_name(n, name):
            raise ManifestException(f"Invalid manifest file [{filename}]: missing required '{name}' element")
        return _fields(n, name, allowXHTML, merge_multiple, filename)
    return check


def _each(name: str, make: Callable[[Any], Any]) -> Check:
    def check(n: Any, filename: str) -> List[Any]:
        try:
            return [make(e) for e in get_nodes_by_name(n, name)]
        except (KeyError, ValueError) as exc:
            raise ManifestException(f"Invalid manifest file [{filename}]: bad <{name}>: {exc}") from None
    return check


def check_platform(name: str) -> Check:
    return _each(name, lambda e: Platform(e.getAttribute("os"), e.getAttribute("version"),
                                          e.getAttribute("notes") or None))


def check_depends(name: str) -> Check:
    """Reader of a package's ``<depend package=...>`` elements (a ``stack=`` one is an error)."""
    def make(e: Any) -> Depend:
        if e.getAttribute("stack"):
            raise ValueError("a package cannot depend on a stack")
        return Depend(e.getAttribute("package"))
    return _each(name, make)


def check_stack_depends(name: str) -> Check:
    return _each(name, lambda e: StackDepend(e.getAttribute("stack")))


def check_rosdeps(name: str) -> Check:
    return _each(name, lambda e: ROSDep(e.getAttribute("name")))


def check_exports(name: str) -> Check:
    def check(n: Any, filename: str) -> List[Export]:
        return [Export(c.tagName, dict(c.attributes.items()), _text(c.childNodes))
                for e in get_nodes_by_name(n, name) for c in e.childNodes
                if c.nodeType == c.ELEMENT_NODE]
    return check


def check_versioncontrol(name: str) -> Check:
    def check(n: Any, filename: str) -> Optional[VersionControl]:
        found = get_nodes_by_name(n, name)
        if not found:
            return None
        if len(found) > 1:
            raise ManifestException(f"Invalid manifest file [{filename}]: only one <{name}> allowed")
        return VersionControl(found[0].getAttribute("type"), found[0].getAttribute("url") or None)
    return check


def check(name: str, merge_multiple: bool = False) -> Check:
    """The reader of field ``name`` (required, list or optional, as the manifest format says)."""
    special = {"depend": check_depends, "export": check_exports,
               "versioncontrol": check_versioncontrol, "rosdep": check_rosdeps,
               "platform": check_platform}
    if name in special:
        return special[name](name)
    if name in REQUIRED:
        return check_required(name, name in ALLOWXHTML, merge_multiple)
    return check_optional(name, name in ALLOWXHTML, merge_multiple)


# ---------------------------------------------------------------------------------------------
# manifests

class Manifest:
    """A parsed ``manifest.xml`` (``_type`` 'package') or ``stack.xml`` ('stack')."""

    def __init__(self, _type: str = "package") -> None:
        self.description = self.brief = self.author = self.license = self.license_url = ""
        self.url = self.logo = self.status = self.version = self.notes = ""
        self.depends: List[Any] = []
        self.rosdeps: List[ROSDep] = []
        self.exports: List[Export] = []
        self.platforms: List[Platform] = []
        self.versioncontrol: Optional[VersionControl] = None
        self.unknown_tags: List[Any] = []
        self._type = _type

    def __str__(self) -> str:
        return self.xml()

    def get_export(self, tag: str, attr: str) -> List[str]:
        """The ``attr`` values of the exports tagged ``tag`` (e.g. 'python', 'path')."""
        return [v for e in self.exports if e.tag == tag for v in [e.get(attr)] if v is not None]

    def xml(self) -> str:
        brief = f' brief="{self.brief}"' if self.brief else ""
        license_url = f' url="{self.license_url}"' if self.license_url else ""
        lines = [f"<description{brief}>{self.description}</description>",
                 f"<author>{self.author}</author>",
                 f"<license{license_url}>{self.license}</license>"]
        if self.status or self.notes:
            lines.append(f'<review status="{self.status}" notes="{self.notes}" />')
        lines += [f"<{tag}>{value}</{tag}>" for tag, value in (("url", self.url), ("logo", self.logo))
                  if value]
        lines += [d.xml() for d in self.depends] + [r.xml() for r in self.rosdeps]
        lines += [p.xml() for p in self.platforms]
        if self.exports:
            lines.append("<export>\n" + "\n".join("  " + e.xml() for e in self.exports) + "\n</export>")
        if self.versioncontrol:
            lines.append(self.versioncontrol.xml())
        if self.version:
            lines.append(f"<version>{self.version}</version>")
        return f"<{self._type}>\n" + "\n".join("  " + line for line in lines) + f"\n</{self._type}>"


def parse(m: Manifest, string: str, filename: str = "string") -> Manifest:
    """Fill ``m`` from manifest text ``string``; ManifestException when it is invalid."""
    try:
        doc = minidom.parseString(string)
    except Exception as exc:  # expat's errors have no common base worth naming
        raise ManifestException(f"invalid XML: {exc}") from None
    tops = get_nodes_by_name(doc, m._type)
    if len(tops) != 1:
        raise ManifestException(f"manifest must have a single '{m._type}' element")
    top = tops[0]

    def attribute(tag: str, attr: str, default: str = "") -> str:
        found = get_nodes_by_name(top, tag)
        return (found[0].getAttribute(attr) or "") if found else default

    m.description = check("description")(top, filename)
    m.brief = attribute("description", "brief")
    if m._type == "package":
        m.depends = check_depends("depend")(top, filename)
    elif m._type == "stack":
        m.depends = check_stack_depends("depend")(top, filename)
    m.rosdeps = check("rosdep")(top, filename)
    m.platforms = check("platform")(top, filename)
    m.exports = check("export")(top, filename)
    m.versioncontrol = check("versioncontrol")(top, filename)
    m.license = check("license")(top, filename)
    m.license_url = attribute("license", "url")
    m.status = attribute("review", "status", "unreviewed")
    m.notes = attribute("review", "notes")
    m.author = check("author", True)(top, filename)
    m.url = check("url")(top, filename)
    m.version = check("version")(top, filename)
    m.logo = check("logo")(top, filename)
    if m._type == "stack" and (m.exports or m.rosdeps):
        raise ManifestException("stack manifests are not allowed to have exports or rosdeps")
    m.unknown_tags = [e for e in top.childNodes
                      if e.nodeType == e.ELEMENT_NODE and e.tagName not in VALID]
    return m


def parse_file(m: Manifest, file: str) -> Manifest:  # noqa: A002 - roslib's parameter name
    """Fill ``m`` from the manifest file ``file``."""
    if not file:
        raise ValueError("Missing manifest file argument")
    if not os.path.isfile(file):
        raise ValueError(f"Invalid/non-existent manifest file: {file}")
    with open(file, encoding="utf-8") as f:
        text = f.read()
    try:
        return parse(m, text, file)
    except ManifestException as exc:
        raise ManifestException(f"Invalid manifest file [{os.path.abspath(file)}]: {exc}") from None


# ---------------------------------------------------------------------------------------------
# stacks

class StackManifest(Manifest):
    """A parsed ``stack.xml``."""

    def __init__(self) -> None:
        super().__init__("stack")


def rosstack() -> Any:
    """A ``rospkg.RosStack`` over the roots minros searches (stacks and metapackages)."""
    import rospkg

    return rospkg.RosStack(ros_paths=[str(p) for p in packages.search_roots()])


def get_stack_dir(stack: str, env: Any = None) -> str:
    """The folder of ``stack``; InvalidROSStackException when there is none."""
    import rospkg

    try:
        return str(rosstack().get_path(stack))
    except rospkg.ResourceNotFound:
        raise InvalidROSStackException(stack) from None


def stack_file(stack: str, required: bool = True) -> Optional[str]:
    """The path of ``stack``'s ``stack.xml`` (None, or an error when ``required``, if absent)."""
    path = os.path.join(get_stack_dir(stack), STACK_FILE)
    if not os.path.isfile(path):
        if required:
            raise InvalidROSStackException(f"Stack '{stack}' has no {STACK_FILE} (it is a catkin metapackage?)")
        return None
    return path


def parse_stack_file(file: str) -> StackManifest:  # noqa: A002
    m = StackManifest()
    parse_file(m, file)
    return m


def parse_stack(string: str, filename: str = "string") -> StackManifest:
    m = StackManifest()
    parse(m, string, filename)
    return m


def stack_of(pkg: str, env: Any = None) -> Optional[str]:
    """The rosbuild stack (a folder with ``stack.xml`` above the package) holding ``pkg``;
    None when it is in none. InvalidROSPkgException when ``pkg`` is not found."""
    d = packages.get_pkg_dir(pkg, True)
    while d and os.path.dirname(d) != d:
        if os.path.exists(os.path.join(d, STACK_FILE)):
            return os.path.basename(d)
        d = os.path.dirname(d)
    return None


def list_stacks(env: Any = None) -> List[str]:
    """The names of every stack (rosbuild stack or catkin metapackage) on the package path."""
    return list(rosstack().list())


def list_stacks_by_path(path: str, stacks: Optional[List[str]] = None,
                        cache: Optional[Dict[str, str]] = None) -> List[str]:
    """Stacks (folders with ``stack.xml``) below ``path``, appended to ``stacks``; ``cache``
    gets ``{stack: folder}``. Packages are leaves: nothing below them is searched."""
    stacks = [] if stacks is None else stacks
    for d, dirs, files in os.walk(path, topdown=True, followlinks=True):
        if STACK_FILE in files:
            name = os.path.basename(d)
            if name not in stacks:
                stacks.append(name)
                if cache is not None:
                    cache[name] = d
            dirs[:] = []
        elif packages.MANIFEST_FILE in files or "rospack_nosubdirs" in files:
            dirs[:] = []
        else:
            dirs[:] = [x for x in dirs if not x.startswith(".")]
    return stacks


def expand_to_packages(names: Sequence[str], env: Any = None) -> Tuple[List[str], List[str]]:
    """``(packages, not_found)``: stacks among ``names`` expanded to their packages."""
    import rospkg

    return rospkg.expand_to_packages(list(names), packages.rospack(), rosstack())


def get_stack_version(stack: str, env: Any = None) -> Optional[str]:
    """The version of ``stack`` (see :func:`get_stack_version_by_dir`), None if unversioned."""
    return get_stack_version_by_dir(get_stack_dir(stack))


_CMAKE_VERSION = re.compile(r"^\s*rosbuild_make_distribution\s*\(\s*([^\s)]+)", re.MULTILINE)


def get_stack_version_by_dir(stack_dir: str) -> Optional[str]:
    """The version of the stack in ``stack_dir``: the ``<version>`` of its ``stack.xml`` or
    (a catkin metapackage) ``package.xml``, else rosbuild's ``rosbuild_make_distribution(V)``
    in its CMakeLists.txt; None when it has none."""
    manifest = os.path.join(stack_dir, STACK_FILE)
    if os.path.isfile(manifest):
        version = parse_stack_file(manifest).version
        if version:
            return version
    version = packages.manifest_version(Path(stack_dir))
    if version:
        return version
    try:
        with open(os.path.join(stack_dir, "CMakeLists.txt"), encoding="utf-8") as f:
            match = _CMAKE_VERSION.search(f.read())
    except OSError:
        return None
    return match.group(1) if match else None
