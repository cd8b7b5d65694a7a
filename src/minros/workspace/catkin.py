"""catkin workspace tools without CMake: init, create a package, "make" a devel space.

minros packages are Python and message definitions, so ``catkin_make`` has nothing to
compile. What it must do is what a user relies on afterwards: a ``build/`` and a ``devel/``
folder, ``devel/setup.{sh,bash,zsh}`` that put the workspace's packages on
ROS_PACKAGE_PATH, ``devel/bin`` and minros's own interpreter folder on PATH and
``devel/lib/python3/dist-packages`` on PYTHONPATH, and importable ``<pkg>.msg`` / ``<pkg>.srv``
modules for the workspace's message packages (``.action`` files included), and
``<pkg>.cfg.<Name>Config`` modules for their dynamic_reconfigure ``.cfg`` scripts. Console
output follows catkin's wording where a user sees it (``catkin_create_pkg``) and
catkin_make's shape elsewhere.
"""

from __future__ import annotations

import getpass
import os
import re
import shlex
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, List, Sequence

#: The file ``catkin_init_workspace`` links src/CMakeLists.txt to (as catkin's toplevel.cmake).
TOPLEVEL_CMAKE = Path(__file__).resolve().parent / "share" / "toplevel.cmake"

# catkin_pkg's naming convention (a warning, not an error, as in catkin_create_pkg)
_NAME_CONVENTION = re.compile(r"^[a-z][a-z0-9_-]*$")
# what a package folder name may be at all (it becomes a path component and a CMake project)
_LEGAL_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


class WorkspaceError(Exception):
    """An expected failure of a workspace tool; its text is the one line the user sees."""


Print = Callable[[str], None]


def _print(line: str) -> None:
    print(line, flush=True)


# --------------------------------------------------------------------------- manifests

@dataclass
class Manifest:
    """The parts of a package.xml the workspace tools use."""

    name: str
    path: Path
    version: str = "0.0.0"
    format: int = 1
    build_depends: List[str] = field(default_factory=list)
    run_depends: List[str] = field(default_factory=list)


def read_manifest(package_dir: Path) -> Manifest:
    """Parse ``package_dir/package.xml`` (formats 1-3); raises WorkspaceError if malformed."""
    path = Path(package_dir) / "package.xml"
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise WorkspaceError(f"{path}: cannot read package manifest: {exc}") from None
    name_el = root.find("name")
    if root.tag != "package" or name_el is None or not (name_el.text or "").strip():
        raise WorkspaceError(f"{path}: not a package manifest (needs <package> with a <name>)")
    fmt = int(root.get("format", "1")) if root.get("format", "1").isdigit() else 1
    build: List[str] = []
    run: List[str] = []
    for child in root:
        text = (child.text or "").strip()
        if not text:
            continue
        if child.tag in ("depend", "build_depend", "buildtool_depend"):
            build.append(text)
        if child.tag in ("depend", "exec_depend", "run_depend", "build_export_depend"):
            run.append(text)
    version_el = root.find("version")
    return Manifest(
        name=name_el.text.strip(), path=Path(package_dir), format=fmt,
        version=(version_el.text or "0.0.0").strip() if version_el is not None else "0.0.0",
        build_depends=list(dict.fromkeys(build)), run_depends=list(dict.fromkeys(run)),
    )


def find_workspace_packages(src: Path) -> List[Manifest]:
    """Packages below ``src`` (not inside another package; CATKIN_IGNORE and dot-folders skipped)."""
    found: List[Manifest] = []

    def walk(folder: Path) -> None:
        if (folder / "package.xml").is_file():
            found.append(read_manifest(folder))
            return
        if (folder / "CATKIN_IGNORE").exists():
            return
        try:
            children = sorted(p for p in folder.iterdir() if p.is_dir() and not p.name.startswith("."))
        except OSError:
            return
        for child in children:
            walk(child)

    walk(Path(src))
    names: Dict[str, Path] = {}
    for manifest in found:
        if manifest.name in names:
            raise WorkspaceError(
                f"Multiple packages found with the same name \"{manifest.name}\":\n"
                f"- {names[manifest.name]}\n- {manifest.path}")
        names[manifest.name] = manifest.path
    return found


def topological_order(manifests: Sequence[Manifest]) -> List[Manifest]:
    """Workspace packages ordered so that each comes after the ones it build-depends on."""
    by_name = {m.name: m for m in manifests}
    ordered: List[Manifest] = []
    state: Dict[str, int] = {}  # 1 visiting, 2 done

    def visit(m: Manifest, chain: List[str]) -> None:
        if state.get(m.name) == 2:
            return
        if state.get(m.name) == 1:
            raise WorkspaceError("circular dependency between packages: " + " -> ".join(chain + [m.name]))
        state[m.name] = 1
        for dep in sorted(set(m.build_depends) | set(m.run_depends)):
            if dep in by_name and dep != m.name:
                visit(by_name[dep], chain + [m.name])
        state[m.name] = 2
        ordered.append(m)

    for m in sorted(manifests, key=lambda m: m.name):
        visit(m, [])
    return ordered


# --------------------------------------------------------------------------- catkin_init_workspace

def init_workspace(src_dir: Path, out: Print = _print) -> Path:
    """Create ``src_dir/CMakeLists.txt`` pointing at the toplevel CMake file, as catkin does."""
    src_dir = Path(src_dir).absolute()
    if not src_dir.is_dir():
        raise WorkspaceError(f"Workspace path '{src_dir}' does not exist")
    target = src_dir / "CMakeLists.txt"
    if target.exists() or target.is_symlink():
        raise WorkspaceError(f"File '{target}' already exists")
    try:
        target.symlink_to(TOPLEVEL_CMAKE)
        out(f'Creating symlink "{target}" pointing to "{TOPLEVEL_CMAKE}"')
    except OSError:  # file systems without symlinks: a copy does the same job
        target.write_text(TOPLEVEL_CMAKE.read_text())
        out(f'Creating file "{target}" as a copy of "{TOPLEVEL_CMAKE}"')
    return target


# --------------------------------------------------------------------------- catkin_create_pkg

def _package_xml(name: str, deps: Sequence[str], version: str, description: str,
                 license_: str, maintainer: str, email: str, authors: Sequence[str]) -> str:
    lines = [
        '<?xml version="1.0"?>',
        '<package format="2">',
        f"  <name>{name}</name>",
        f"  <version>{version}</version>",
        f"  <description>{_xml_escape(description)}</description>",
        "",
        "  <!-- At least one maintainer; one person per tag. -->",
        f'  <maintainer email="{_xml_escape(email)}">{_xml_escape(maintainer)}</maintainer>',
        "",
        "  <!-- At least one license; e.g. BSD, MIT, Apache-2.0, GPLv3. -->",
        f"  <license>{_xml_escape(license_)}</license>",
        "",
        "  <!-- Optional: <url type=\"website\">, <author email=\"...\">. -->",
    ]
    for author in authors:
        lines.append(f"  <author>{_xml_escape(author)}</author>")
    lines += [
        "",
        "  <!-- Dependencies: <depend> means build and exec; message packages need",
        "       <build_depend>message_generation</build_depend> and",
        "       <exec_depend>message_runtime</exec_depend>. -->",
        "  <buildtool_depend>catkin</buildtool_depend>",
    ]
    for tag in ("build_depend", "build_export_depend", "exec_depend"):
        lines += [f"  <{tag}>{dep}</{tag}>" for dep in deps]
    lines += [
        "",
        "  <export>",
        "    <!-- Other tools can request additional information be placed here -->",
        "  </export>",
        "</package>",
        "",
    ]
    return "\n".join(lines)


def _xml_escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")


def _cmakelists(name: str, deps: Sequence[str]) -> str:
    if deps:
        find = "find_package(catkin REQUIRED COMPONENTS\n" + "".join(f"  {d}\n" for d in deps) + ")"
    else:
        find = "find_package(catkin REQUIRED)"
    include = "  ${catkin_INCLUDE_DIRS}\n" if deps else ""
    own_include = "# include\n" if "roscpp" in deps else ""
    return f"""cmake_minimum_required(VERSION 3.0.2)
project({name})

## Packages this one builds against (catkin components).
{find}

## Python: uncomment if the package has a setup.py for its module in src/{name}/.
# catkin_python_setup()

## Messages and services: list the files of msg/ and srv/, then generate them
## (package.xml also needs message_generation / message_runtime).
# add_message_files(FILES Message1.msg)
# add_service_files(FILES Service1.srv)
# generate_messages(DEPENDENCIES std_msgs)

## What dependent packages get from this one.
catkin_package(
#  INCLUDE_DIRS include
#  LIBRARIES {name}
#  CATKIN_DEPENDS {' '.join(deps)}
)

include_directories(
{own_include}{include})

## Python scripts to install (rosrun finds them in the source space already).
# catkin_install_python(PROGRAMS scripts/my_node.py
#   DESTINATION ${{CATKIN_PACKAGE_BIN_DESTINATION}}
# )
"""


def create_package(name: str, deps: Sequence[str], parent: Path, *, version: str = "0.0.0",
                   description: str | None = None, license_: str = "TODO",
                   maintainer: str | None = None, authors: Sequence[str] = (),
                   out: Print = _print, warn: Print = _print) -> Path:
    """Create package ``name`` in ``parent`` the way ``catkin_create_pkg`` lays it out."""
    if not _LEGAL_NAME.match(name):
        raise WorkspaceError(f"Package name '{name}' is not a valid folder name")
    if not _NAME_CONVENTION.match(name):
        warn(f'WARNING: Package name "{name}" does not follow the naming conventions. It should start '
             "with a lower case letter and only contain lower case letters, digits, underscores, and dashes.")
    for dep in deps:
        if not _LEGAL_NAME.match(dep):
            raise WorkspaceError(f"Dependency name '{dep}' is not a valid package name")
    deps = sorted(dict.fromkeys(deps))
    pkg = Path(parent).absolute() / name
    for existing in (pkg / "package.xml", pkg / "CMakeLists.txt"):
        if existing.exists():
            raise WorkspaceError(f"File exists: {existing}")
    user = maintainer or _user_name()
    pkg.mkdir(parents=True, exist_ok=True)
    (pkg / "package.xml").write_text(_package_xml(
        name, deps, version, description or f"The {name} package", license_, user,
        f"{user}@todo.todo", authors))
    out(f"Created file {name}/package.xml")
    (pkg / "CMakeLists.txt").write_text(_cmakelists(name, deps))
    out(f"Created file {name}/CMakeLists.txt")
    if "roscpp" in deps:
        (pkg / "include" / name).mkdir(parents=True, exist_ok=True)
        out(f"Created folder {name}/include/{name}")
    if "roscpp" in deps or "rospy" in deps:
        (pkg / "src").mkdir(exist_ok=True)
        out(f"Created folder {name}/src")
    out(f"Successfully created files in {pkg}. Please adjust the values in package.xml.")
    return pkg


def _user_name() -> str:
    try:
        return getpass.getuser()
    except Exception:  # no passwd entry (containers): catkin falls back to the same
        return "user"


# --------------------------------------------------------------------------- catkin_make

def _venv_bin() -> str:
    """The folder of the interpreter running minros (the venv's bin), for PATH."""
    return str(Path(sys.executable).absolute().parent)


def setup_sh(workspace: Path) -> str:
    """Text of devel/setup.sh for ``workspace`` (POSIX sh; bash and zsh source it too)."""
    ws = Path(workspace).absolute()
    devel = ws / "devel"
    q = shlex.quote
    return f"""#!/usr/bin/env sh
# generated by minros catkin_make for the workspace {ws}
# Puts the workspace's packages, programs and Python modules in front of what is already set,
# without duplicating entries when sourced again.

_minros_prepend() {{
  # $1: variable name, $2: entry to put first
  eval "_minros_old=\\${{$1:-}}"
  _minros_new="$2"
  _minros_ifs=$IFS
  IFS=:
  for _minros_e in $_minros_old; do
    if [ -n "$_minros_e" ] && [ "$_minros_e" != "$2" ]; then
      _minros_new="$_minros_new:$_minros_e"
    fi
  done
  IFS=$_minros_ifs
  eval "export $1=\\"\\$_minros_new\\""
  unset _minros_old _minros_new _minros_ifs _minros_e
}}

_minros_prepend PATH {q(_venv_bin())}
_minros_prepend PATH {q(str(devel / 'bin'))}
_minros_prepend PYTHONPATH {q(str(devel / 'lib' / 'python3' / 'dist-packages'))}
_minros_prepend LD_LIBRARY_PATH {q(str(devel / 'lib'))}
_minros_prepend CMAKE_PREFIX_PATH {q(str(devel))}
_minros_prepend ROS_PACKAGE_PATH {q(str(ws / 'src'))}
unset -f _minros_prepend

export ROS_DISTRO=noetic
export ROS_VERSION=1
export ROS_PYTHON_VERSION=3
export ROS_ETC_DIR={q(str(devel / 'etc' / 'ros'))}
: "${{ROS_MASTER_URI:=http://localhost:11311}}"
export ROS_MASTER_URI
"""


def setup_bash(workspace: Path) -> str:
    devel = Path(workspace).absolute() / "devel"
    return ("#!/usr/bin/env bash\n# generated by minros catkin_make\n"
            f". {shlex.quote(str(devel / 'setup.sh'))}\n")


def setup_zsh(workspace: Path) -> str:
    devel = Path(workspace).absolute() / "devel"
    # setup.sh relies on POSIX word splitting, which zsh only does in sh emulation.
    return ("#!/usr/bin/env zsh\n# generated by minros catkin_make\n"
            f'emulate sh -c ". {shlex.quote(str(devel / "setup.sh"))}"\n')


_ENV_SH = """#!/usr/bin/env sh
# generated by minros catkin_make: run a command in the workspace's environment
if [ $# -eq 0 ]; then
  echo "Usage: env.sh COMMANDS"
  echo "Calling env.sh without arguments is not supported anymore. Instead spawn a subshell and source a setup file manually."
  exit 1
fi
. "$(cd "$(dirname "$0")" && pwd)/setup.sh"
exec "$@"
"""


#: what an earlier catkin_make's relay to a package's sources began with (rewritten now)
_RELAY_MARK = "# minros catkin_make: relay to the package's Python sources"


def _write_overlay_init(folder: Path, module_src: Path | None) -> None:
    """The devel-space ``__init__.py`` of a package (minros.workspace.devel): the package's
    sources and its underlay behind the stand-ins written here. One a user wrote (no minros
    mark) is left alone."""
    from minros.workspace.devel import MARK, init_text

    init = folder / "__init__.py"
    folder.mkdir(parents=True, exist_ok=True)
    if init.exists():
        try:
            current = init.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return
        if current.strip() and not any(mark in current for mark in (*_WRITTEN_BY_MINROS, MARK)):
            return
    init.write_text(init_text(str(folder), str(module_src) if module_src else None))


def _interface_counts(pkg: Path) -> Dict[str, int]:
    return {kind: len(list((pkg / kind).glob(f"*.{kind}"))) for kind in ("msg", "srv", "action", "cfg")}


#: what genaction makes of ``Name.action``: these seven message types
_ACTION_TYPES = ("Action", "ActionGoal", "ActionResult", "ActionFeedback", "Goal", "Result",
                 "Feedback")


def _check_definition(path: Path, build: Callable[[str], object], type_name: str) -> None:
    try:
        build(type_name)
    except Exception as exc:  # a malformed definition: one line naming the file
        text = str(exc).replace("\n", " ")
        raise WorkspaceError(f"{path}: {text}") from None


def _check_cfg_scripts(manifest: Manifest, out: Print) -> Dict[str, Path]:
    """Run each ``cfg/*.cfg`` of the package (a broken one fails the build with one line
    naming file and line); ``{<Name>Config: script}``."""
    from minros.dynamic_reconfigure.generator import CfgError, run_cfg

    modules = {}
    for path in sorted((manifest.path / "cfg").glob("*.cfg")):
        try:
            gen = run_cfg(path, out=out)
        except CfgError as exc:
            raise WorkspaceError(str(exc)) from None
        modules[f"{gen.name}Config"] = path
    return modules


def _write_cfg_modules(manifest: Manifest, dist_packages: Path, out: Print) -> None:
    """generate_dynamic_reconfigure_options: run each ``cfg/*.cfg`` (a broken one fails the
    build with one line naming file and line) and write ``<pkg>.cfg.<Name>Config`` modules,
    which rerun the script on import, so later edits need no rebuild."""
    from minros.dynamic_reconfigure.cfg_import import write_stubs

    modules = _check_cfg_scripts(manifest, out)
    init = dist_packages / manifest.name / "__init__.py"
    if not init.exists():
        init.parent.mkdir(parents=True, exist_ok=True)
        init.write_text(f'"""{manifest.name}: written by minros catkin_make."""\n')
    write_stubs(manifest.name, dist_packages, modules)


def _write_message_stubs(manifest: Manifest, dist_packages: Path, src: Path,
                         out: Print = _print, stubs: bool = True) -> None:
    """Check the package's .msg/.srv files and write its ``<pkg>.msg``/``<pkg>.srv`` stubs.

    The stubs (helper A's writer) generate classes on first use from the package's files, found
    on ROS_PACKAGE_PATH; here the workspace's src is put in front for the check, so a malformed
    definition fails the build, as genmsg would, instead of the first node that imports it.
    """
    from minros import msgs  # imported late: only packages with messages need it

    name = manifest.name
    previous = os.environ.get("ROS_PACKAGE_PATH")
    os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join([str(src)] + ([previous] if previous else []))
    try:
        for kind, getter in (("msg", msgs.get_message_class), ("srv", msgs.get_service_class)):
            for path in sorted((manifest.path / kind).glob(f"*.{kind}")):
                _check_definition(path, getter, f"{name}/{path.stem}")
        for path in sorted((manifest.path / "action").glob("*.action")):
            # add_action_files: the seven generated types must build, as genaction's output
            out(f"Generating .msg files for action {name}/{path.stem} {path}")
            for suffix in _ACTION_TYPES:
                _check_definition(path, msgs.get_message_class, f"{name}/{path.stem}{suffix}")
        if stubs:
            kinds = [kind for kind, folders in (("msg", ("msg", "action")), ("srv", ("srv",)))
                     if any((manifest.path / f).is_dir() for f in folders)]
            msgs.write_stub_package(name, dist_packages, kinds)
    finally:
        if previous is None:
            os.environ.pop("ROS_PACKAGE_PATH", None)
        else:
            os.environ["ROS_PACKAGE_PATH"] = previous


def shipped_python_packages() -> frozenset:
    """The top-level Python packages minros installs: its stand-ins under ROS names (rospy,
    actionlib, tf, std_msgs, ...). A devel space must not put a package of one of these names
    on PYTHONPATH: it would come first and hide minros's library (an ``actionlib`` holding only
    message stubs has no SimpleActionClient)."""
    import importlib.metadata

    try:
        text = importlib.metadata.distribution("minros").read_text("top_level.txt") or ""
    except importlib.metadata.PackageNotFoundError:
        text = ""
    names = set(text.split())
    if not names:  # running from a source tree that was never installed
        stubs = Path(__file__).resolve().parents[3] / "stubs"
        if stubs.is_dir():
            names = {p.name for p in stubs.iterdir() if (p / "__init__.py").is_file()}
    names.discard("minros")
    # _minros_import_hook: minros's start-up hook, no ROS package
    return frozenset(n for n in names if not n.startswith("_"))


#: texts that mark a devel-space package as written by minros's catkin_make (safe to remove)
_WRITTEN_BY_MINROS = ("provided by minros", "written by minros catkin_make", _RELAY_MARK)


def make_workspace(workspace: Path, *, jobs: int | None = None, out: Print = _print) -> List[Manifest]:
    """Build the workspace rooted at ``workspace`` (its ``src`` holds the packages)."""
    ws = Path(workspace).absolute()
    src, build, devel, install = ws / "src", ws / "build", ws / "devel", ws / "install"
    if not src.is_dir():
        if (ws / "CMakeLists.txt").exists():  # run inside src/ by mistake, as catkin_make says
            raise WorkspaceError(f'The specified base path "{ws}" contains a CMakeLists.txt but '
                                 '"catkin_make" must be invoked in the root of workspace')
        raise WorkspaceError(f'The specified source space "{src}" does not exist')
    if (ws / "package.xml").exists():
        raise WorkspaceError(
            f"The specified base path \"{ws}\" contains a package but \"catkin_make\" must be invoked "
            "in the root of workspace")
    out(f"Base path: {ws}")
    out(f"Source space: {src}")
    out(f"Build space: {build}")
    out(f"Devel space: {devel}")
    out(f"Install space: {install}")
    if not (src / "CMakeLists.txt").exists():
        init_workspace(src, out=out)
    manifests = topological_order(find_workspace_packages(src))
    build.mkdir(exist_ok=True)
    dist = devel / "lib" / "python3" / "dist-packages"
    for folder in (dist, devel / "bin", devel / "share", devel / "etc" / "ros"):
        folder.mkdir(parents=True, exist_ok=True)
    out("####")
    out(f'#### Running minros catkin build (Python and messages; nothing to compile) in "{build}"')
    out("####")
    out(f"-- Using CATKIN_DEVEL_PREFIX: {devel}")
    out(f"-- Using Python: {sys.executable}")
    out("-- ~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~")
    out(f"-- ~~  traversing {len(manifests)} packages in topological order:")
    for m in manifests:
        out(f"-- ~~  - {m.name}")
    out("-- ~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~")
    total = max(len(manifests), 1)
    shipped = shipped_python_packages()
    for index, m in enumerate(manifests, 1):
        out(f"-- +++ processing catkin package: '{m.name}'")
        out(f"-- ==> add_subdirectory({m.path.relative_to(src)})")
        counts = _interface_counts(m.path)
        module_src = m.path / "src" / m.name
        has_python = (module_src / "__init__.py").is_file()
        if m.name in shipped:
            # a devel space puts the workspace's package first: its modules and messages win,
            # and what it lacks comes from minros's package of that name (as an underlay)
            out(f"-- {m.name}: the workspace's package comes before minros's '{m.name}'; "
                "what it lacks comes from minros's")
        if counts["msg"] or counts["srv"] or counts["action"]:
            messages = counts["msg"] + len(_ACTION_TYPES) * counts["action"]
            out(f"-- {m.name}: {messages} messages, {counts['srv']} services")
            _write_message_stubs(m, dist, src, out)
        if counts["cfg"]:
            _write_cfg_modules(m, dist, out)
        if has_python or (dist / m.name).is_dir():
            _write_overlay_init(dist / m.name, module_src if has_python else None)
        share = devel / "share" / m.name
        share.mkdir(parents=True, exist_ok=True)
        out(f"[{100 * index // total:3d}%] Built target {m.name}")
    (build / "catkin_make.cache").write_text(f"minros catkin_make\nsource {src}\ndevel {devel}\n")
    (devel / ".catkin").write_text(str(src))
    (devel / ".rosinstall").write_text(f"- setup-file:\n    local-name: {devel / 'setup.sh'}\n")
    for name, text in (("setup.sh", setup_sh(ws)), ("setup.bash", setup_bash(ws)),
                       ("setup.zsh", setup_zsh(ws)), ("local_setup.sh", setup_sh(ws)),
                       ("local_setup.bash", setup_bash(ws)), ("local_setup.zsh", setup_zsh(ws)),
                       ("env.sh", _ENV_SH)):
        path = devel / name
        path.write_text(text)
        path.chmod(0o755 if name == "env.sh" else 0o644)
    if not manifests:
        out("[100%] Nothing to build (no packages in the source space)")
    return manifests
