"""roswtf's checks of an installation and of packages and stacks (roswtf.packages,
roswtf.stacks, roswtf.rosdep_db, roswtf.py_pip_deb_checks, roswtf.plugins).

Each module's ``warnings`` and ``errors`` are lists of (rule, message format) as in roswtf;
``wtf_check(ctx)`` runs them into the context (minros.cli.wtf's WtfContext). The package and
stack rules read the rosbuild-era files (CMakeLists.txt's ``rospack()``, manifest.xml's cpp
exports and lflags, stack.xml's depends) through rospkg and minros's package lookup;
``load_plugins`` imports the modules packages export as ``<roswtf plugin="..."/>``.
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
from typing import Any, Callable, Dict, List, Optional, Tuple

from minros import packages
from minros.cli.wtf import Rule, WtfContext, error_rule, warning_rule


def _run(ctx: WtfContext, warnings: List[Rule], errors: List[Rule]) -> None:
    for rule in warnings:
        warning_rule(rule, rule[0](ctx), ctx)
    for rule in errors:
        error_rule(rule, rule[0](ctx), ctx)


def is_executable(path: str) -> bool:
    """Whether ``path`` is a file this user may run."""
    return os.path.isfile(path) and os.access(path, os.X_OK)


# -- roswtf.rosdep_db -----------------------------------------------------------------------

def get_user_home_directory() -> str:
    return os.path.expanduser("~")


def rosdep_database_updated_check(ctx: WtfContext) -> Optional[str]:
    """rosdep's source cache must exist (``rosdep update`` writes it)."""
    index = os.path.join(get_user_home_directory(), ".ros", "rosdep", "sources.cache", "index")
    if not os.path.exists(index):
        return "Please update rosdep database with 'rosdep update'."
    return None


rosdep_warnings: List[Rule] = [(rosdep_database_updated_check, "ROS Dep database not updated: ")]
rosdep_errors: List[Rule] = []


def wtf_check_rosdep(ctx: WtfContext) -> None:
    _run(ctx, rosdep_warnings, rosdep_errors)


# -- roswtf.py_pip_deb_checks ----------------------------------------------------------------

python_prefix = "python3"
py_to_deb_core_packages = {"catkin_pkg": "python3-catkin-pkg", "rospkg": "python3-rospkg",
                           "rosdep2": "python3-rosdep"}
py_to_deb_optional_packages = {"rosinstall": "python3-rosinstall"}
py_to_deb_release_packages = {"bloom": "python3-bloom", "rosrelease": "python3-rosrelease"}


def get_host_os() -> str:
    """The operating system's name as rospkg detects it (``ubuntu``, ``debian``, ...)."""
    import rospkg.os_detect

    try:
        return str(rospkg.os_detect.OsDetect().detect_os()[0])
    except rospkg.os_detect.OsNotDetected:
        return "unknown"


def is_host_os_ubuntu() -> bool:
    return get_host_os() == "ubuntu"


def is_debian_package_installed(deb_pkg: str) -> bool:
    """Whether dpkg knows ``deb_pkg`` (bounded; False without dpkg)."""
    try:
        return subprocess.run(["dpkg", "-l", deb_pkg], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, timeout=10).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def is_a_pip_path_on_ubuntu(path: str) -> bool:
    return "/usr/local" in path


def is_python_package_installed(python_pkg: str) -> bool:
    try:
        importlib.import_module(python_pkg)
        return True
    except ImportError:
        return False


def is_python_package_installed_via_pip_on_ubuntu(python_pkg: str) -> bool:
    try:
        module = importlib.import_module(python_pkg)
    except ImportError:
        return False
    return is_a_pip_path_on_ubuntu(getattr(module, "__file__", "") or "")


def python_module_install_check(ctx: WtfContext) -> Optional[str]:
    missing = "".join(f"{p} -- " for p in py_to_deb_core_packages
                      if not is_python_package_installed(p))
    return missing or None


def deb_install_check_on_ubuntu(ctx: WtfContext) -> Optional[str]:
    if not is_host_os_ubuntu():
        return None
    missing = "".join(f"{p} ({d}) -- " for p, d in py_to_deb_core_packages.items()
                      if not is_debian_package_installed(d))
    return missing or None


def pip_install_check_on_ubuntu(ctx: WtfContext) -> Optional[str]:
    if not is_host_os_ubuntu():
        return None
    names = [*py_to_deb_core_packages, *py_to_deb_optional_packages, *py_to_deb_release_packages]
    found = "".join(f"{p} -- " for p in names if is_python_package_installed_via_pip_on_ubuntu(p))
    return found or None


pip_deb_warnings: List[Rule] = [
    (python_module_install_check, "You are missing core ROS Python modules: "),
    (pip_install_check_on_ubuntu,
     "You have pip installed packages on Ubuntu, remove and install using Debian packages: "),
    (deb_install_check_on_ubuntu,
     "You are missing Debian packages for core ROS Python modules: "),
]
pip_deb_errors: List[Rule] = []


def wtf_check_pip_deb(ctx: WtfContext) -> None:
    _run(ctx, pip_deb_warnings, pip_deb_errors)


# -- roswtf.packages --------------------------------------------------------------------------

PACKAGE_FILE = "package.xml"


def _pkg_dir(pkg: str) -> Optional[str]:
    return packages.get_pkg_dir(pkg, required=False)


def _manifest(pkg: str) -> Any:
    """The package's rosbuild manifest.xml, parsed by rospkg, or None (a catkin package)."""
    import rospkg.manifest

    folder = _pkg_dir(pkg)
    if folder is None or not os.path.isfile(os.path.join(folder, "manifest.xml")):
        return None
    try:
        return rospkg.manifest.parse_manifest_file(folder, "manifest.xml")
    except rospkg.manifest.InvalidManifest:
        return None


def manifest_valid(ctx: WtfContext) -> List[str]:
    manifest = getattr(ctx, "manifest", None)
    if manifest is None:
        return []
    return [f"<{t.tagName}>" for t in getattr(manifest, "unknown_tags", [])]


def _manifest_msg_srv_export(ctx: WtfContext, type_: str) -> List[str]:
    found = []
    for pkg in ctx.pkgs:
        folder = _pkg_dir(pkg)
        if folder is None or not os.path.isdir(os.path.join(folder, type_)):
            continue
        if not any(f.endswith("." + type_) for f in os.listdir(os.path.join(folder, type_))):
            continue
        manifest = _manifest(pkg)
        if manifest is None:
            continue
        # rospkg expands ${prefix} to the package's folder
        includes = (f"-I${{prefix}}/{type_}/cpp", f"-I{folder}/{type_}/cpp")
        if any(i in flags for flags in manifest.get_export("cpp", "cflags") for i in includes):
            found.append(pkg)
    return found


def manifest_msg_srv_export(ctx: WtfContext) -> List[str]:
    """Packages whose manifest still exports the msg/srv C++ include flags rosbuild once
    needed."""
    msgs = set(_manifest_msg_srv_export(ctx, "msg"))
    srvs = set(_manifest_msg_srv_export(ctx, "srv"))
    return ([f"{p}: -I${{prefix}}/msg/cpp -I${{prefix}}/srv/cpp" for p in sorted(msgs & srvs)]
            + [f"{p}: -I${{prefix}}/msg/cpp" for p in sorted(msgs - srvs)]
            + [f"{p}: -I${{prefix}}/srv/cpp" for p in sorted(srvs - msgs)])


def _check_for_rpath_flags(pkg: str, lflags: str) -> Optional[str]:
    """A ``-L`` without its ``-Wl,-rpath`` (or the reverse) in ``lflags``."""
    if not lflags:
        return None
    args = lflags.split()
    libs: List[str] = []
    rpaths: List[str] = []
    i = 0
    while i < len(args):
        flag = args[i]
        if flag.startswith("-L") and len(flag) > 2:
            libs.append(os.path.normpath(flag[2:]))
        elif flag == "-L" and i + 1 < len(args):
            i += 1
            libs.append(os.path.normpath(args[i]))
        elif flag.startswith("-Wl") and len(flag) > 3:
            parts = flag.split(",")
            j = 1
            while j < len(parts) - 1:
                if parts[j] == "-rpath":
                    rpaths.append(os.path.normpath(parts[j + 1]))
                    j += 2
                else:
                    j += 1
        i += 1
    for f in libs:
        if f not in rpaths:
            return f'{pkg}: found flag "-L{f}", but no matching "-Wl,-rpath,{f}"'
    for f in rpaths:
        if f not in libs:
            return f'{pkg}: found flag "-Wl,-rpath,{f}", but no matching "-L{f}"'
    return None


def manifest_rpath_flags(ctx: WtfContext) -> List[str]:
    found = []
    for pkg in ctx.pkgs:
        manifest = _manifest(pkg)
        lflags = " ".join(manifest.get_export("cpp", "lflags")) if manifest is not None else ""
        folder = _pkg_dir(pkg) or ""
        problem = _check_for_rpath_flags(pkg, lflags.replace("${prefix}", folder))
        if problem:
            found.append(problem)
    return found


def cmakelists_package_valid(ctx: WtfContext) -> List[str]:
    """Packages whose CMakeLists.txt calls ``rospack(other)`` rather than ``rosbuild_init()``."""
    wrong = []
    for pkg in ctx.pkgs:
        path = os.path.join(_pkg_dir(pkg) or "", "CMakeLists.txt")
        if not os.path.isfile(path):
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            for line in f:
                line = line.strip().replace(" ", "")
                if line.startswith("rospack("):
                    if not line.startswith(f"rospack({pkg})"):
                        wrong.append(pkg)
                    break
                if line.startswith("rosbuild_init()"):
                    break
    return [p for p in wrong if p != "rospack"]


packages_warnings: List[Rule] = [
    (cmakelists_package_valid, "The following packages have incorrect rospack() declarations "
                               "in CMakeLists.txt.\nPlease switch to using rosbuild_init():"),
    (manifest_msg_srv_export, "The following packages have msg/srv-related cflags exports that "
                              "are no longer necessary\n\t<export>\n\t\t<cpp cflags=\"...\"\n"
                              "\t</export>:"),
    (manifest_valid, "%(pkg)s/manifest.xml has unrecognized tags:"),
]
packages_errors: List[Rule] = [
    (manifest_rpath_flags, "The following packages have rpath issues in manifest.xml:"),
]


def wtf_check_packages(ctx: WtfContext) -> None:
    if ctx.pkgs:
        _run(ctx, packages_warnings, packages_errors)


# -- roswtf.stacks ----------------------------------------------------------------------------

def manifest_depends(ctx: WtfContext) -> List[str]:
    """stack.xml depends on stacks that do not exist."""
    import rospkg

    rosstack = rospkg.RosStack()
    known = rosstack.list()
    found = []
    for stack in ctx.stacks:
        try:
            manifest = rosstack.get_manifest(stack)
            path = os.path.join(rosstack.get_path(stack), "stack.xml")
        except rospkg.ResourceNotFound:
            continue  # another rule's
        found += [f"{path} ({d} does not exist)" for d in manifest.depends if d.name not in known]
    return found


stacks_warnings: List[Rule] = [
    (manifest_depends, "The following stack.xml file list invalid dependencies:"),
]
stacks_errors: List[Rule] = []


def wtf_check_stacks(ctx: WtfContext) -> None:
    if ctx.stacks:
        _run(ctx, stacks_warnings, stacks_errors)


# -- roswtf.plugins ---------------------------------------------------------------------------

Plugin = Callable[..., Any]


def load_plugins() -> Tuple[List[Plugin], List[Plugin]]:
    """``(static, online)`` rule functions of the modules packages export as roswtf plugins
    (``<export><roswtf plugin="pkg.module"/></export>``); a plugin that cannot load is named
    on stderr and skipped."""
    static: List[Plugin] = []
    online: List[Plugin] = []
    exports: Dict[str, List[str]] = {}
    try:
        found = packages.plugins("roswtf", "plugin")
    except Exception as exc:  # noqa: BLE001 - no plugins rather than no roswtf
        print(f"Cannot list roswtf plugins: {exc}", file=sys.stderr)
        found = []
    for pkg, value in found:
        exports.setdefault(pkg, []).append(value)
    for pkg, values in exports.items():
        if len(values) != 1:
            print(f"Cannot load plugin [{pkg}]: invalid 'plugin' attribute", file=sys.stderr)
            continue
        module_name = values[0]
        try:
            module = importlib.import_module(module_name)
        except Exception as exc:  # noqa: BLE001 - whatever the plugin raised is the message
            print(f"Unable to load plugin [{module_name}] from package [{pkg}]. Exception "
                  f"thrown: [{exc}]", file=sys.stderr)
            continue
        s_attr = getattr(module, "roswtf_plugin_static", None)
        o_attr = getattr(module, "roswtf_plugin_online", None)
        if s_attr:
            static.append(s_attr)
        if o_attr:
            online.append(o_attr)
        if s_attr is None and o_attr is None:
            print(f"Cannot load plugin [{module_name}]: no 'roswtf_plugin_static' or "
                  "'roswtf_plugin_online' attributes", file=sys.stderr)
        else:
            print("Loaded plugin", module_name)
    return static, online
