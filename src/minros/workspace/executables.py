"""Executables of the packages minros ships, and how rosrun/roslaunch find any executable.

Real ROS installs a package's programs as files (``lib/<pkg>/talker.py``). minros ships its
built-in nodes as Python modules instead, listed in :data:`BUILTIN_NODES`; they run as
``python -m MODULE`` under minros's own interpreter. Everything else is searched in the
package folder the way the ``rosrun`` script searches it (any depth, executable bit required,
``build/`` skipped) plus the package's folders under ``<prefix>/lib/<pkg>`` of CMAKE_PREFIX_PATH.
"""

from __future__ import annotations

import importlib.util
import os
import re
import stat
import sys
from pathlib import Path
from typing import Dict, List

from minros import packages

#: package -> executable name -> module run with ``python -m``. Turtlesim's modules are written
#: separately (minros.nodes.turtlesim); a missing module is reported as "not available".
BUILTIN_NODES: Dict[str, Dict[str, str]] = {
    # roscore's node (``minros core`` runs it too); roslaunch's API starts it as a core node
    "rosout": {"rosout": "minros.nodes.rosout"},
    "rospy_tutorials": {
        "talker.py": "minros.nodes.rospy_tutorials.talker",
        "talker": "minros.nodes.rospy_tutorials.talker",
        "listener.py": "minros.nodes.rospy_tutorials.listener",
        "listener": "minros.nodes.rospy_tutorials.listener",
        "add_two_ints_server": "minros.nodes.rospy_tutorials.add_two_ints_server",
        "add_two_ints_client": "minros.nodes.rospy_tutorials.add_two_ints_client",
    },
    "dynamic_reconfigure": {
        "dynparam": "minros.dynamic_reconfigure.dynparam",
    },
    "turtlesim": {
        "turtlesim_node": "minros.nodes.turtlesim.turtlesim_node",
        "turtle_teleop_key": "minros.nodes.turtlesim.turtle_teleop_key",
        "mimic": "minros.nodes.turtlesim.mimic",
        "draw_square": "minros.nodes.turtlesim.draw_square",
    },
    # `minros web` under the names of the servers it stands in for
    "rosbridge_server": {
        "rosbridge_websocket": "minros.web.rosbridge_websocket",
        "rosbridge_websocket.py": "minros.web.rosbridge_websocket",
    },
    "foxglove_bridge": {"foxglove_bridge": "minros.web.foxglove_bridge"},
    "rosapi": {"rosapi_node": "minros.web.rosapi_node"},
    # tf's tools (minros.tf): names as Debian's tf-tools and tf2-tools install them
    "tf2_ros": {
        "static_transform_publisher": "minros.tf.static_transform_publisher",
        "buffer_server": "minros.nodes.tf2_ros.buffer_server",
    },
    "tf": {
        "static_transform_publisher": "minros.tf.tf_static_transform_publisher",
        "tf_echo": "minros.tf.tf_echo",
        "tf_monitor": "minros.tf.tf_monitor",
        "view_frames": "minros.tf.view_frames",
    },
    "tf2_tools": {
        "view_frames.py": "minros.tf.view_frames",
    },
    # minros sim and the navigation nodes it starts (minros.sim holds their logic)
    "minros_sim": {"sim_node": "minros.nodes.minros_sim.sim_node"},
    "map_server": {
        "map_server": "minros.nodes.map_server.map_server",
        "map_saver": "minros.nodes.map_server.map_saver",
    },
    "move_base": {"move_base": "minros.nodes.move_base.move_base"},
    "turtle_tf": {
        "turtle_tf_broadcaster.py": "minros.nodes.turtle_tf.turtle_tf_broadcaster",
        "turtle_tf_listener.py": "minros.nodes.turtle_tf.turtle_tf_listener",
    },
    # the record and play programs that `rosbag record|play` run in ROS 1, and the tool itself
    "rosbag": {
        "record": "minros.cli.bag_record",
        "play": "minros.cli.bag_play",
        "rosbag": "minros.cli.bag",
    },
    # the command-line tools, which ROS also installs as programs of their packages
    # (`<node pkg="rostopic" type="rostopic" args="pub ...">`)
    "rostopic": {"rostopic": "minros.cli.topic"},
    "rosnode": {"rosnode": "minros.cli.node"},
    "rosparam": {"rosparam": "minros.cli.param"},
    "rosservice": {"rosservice": "minros.cli.service"},
    "rosmsg": {"rosmsg": "minros.cli.msg", "rossrv": "minros.cli.srv"},
    "rosconsole": {"rosconsole": "minros.cli.console"},
    # rostest's own test nodes (<test pkg="rostest" type="hztest">)
    "rostest": {"rostest": "minros.cli.rostest", **{name: f"minros.nodes.rostest.{name}" for name in (
        "hztest", "paramtest", "publishtest", "advertisetest")}},
    "nodelet": {"nodelet": "minros.nodes.nodelet.nodelet"},
    "image_transport": {"republish": "minros.nodes.image_transport.republish"},
    "robot_state_publisher": {
        "robot_state_publisher": "minros.nodes.robot_state_publisher.robot_state_publisher",
        "state_publisher": "minros.nodes.robot_state_publisher.robot_state_publisher"},
    "joint_state_publisher": {
        "joint_state_publisher": "minros.nodes.joint_state_publisher.joint_state_publisher"},
    # PyPI's xacro with minros's package lookup (the package folder holds the same program
    # for <param command="$(find xacro)/xacro ...">)
    "xacro": {"xacro": "minros.nodes.xacro.xacro", "xacro.py": "minros.nodes.xacro.xacro"},
    "tf2_web_republisher": {
        "tf2_web_republisher": "minros.nodes.tf2_web_republisher.tf2_web_republisher"},
    # urdf_parser_py's package (minros.urdf_parser)
    "urdfdom_py": {"display_urdf": "minros.nodes.urdfdom_py.display_urdf"},
    # headless: ROS's axclient is a wxPython window
    "actionlib_tools": {"axclient.py": "minros.nodes.actionlib_tools.axclient",
                        "axclient": "minros.nodes.actionlib_tools.axclient"},
    # topic_tools' programs (minros.topic_tools; ROS ships C++ relay/throttle/drop/mux)
    "topic_tools": {name: f"minros.nodes.topic_tools.{name}" for name in (
        "relay", "throttle", "drop", "mux", "transform", "mux_select", "mux_add",
        "mux_delete", "mux_list", "switch_mux")},
}

# `#!/usr/bin/env python`, `#!/usr/bin/python3`, `#!/usr/bin/env -S python3 -u`...
_PYTHON_SHEBANG = re.compile(rb"^#!\s*(?:/usr/bin/env\s+(?:-S\s+)?)?(?:\S*/)?python[0-9.]*(\s|$)")


class ExecutableError(Exception):
    """rosrun/roslaunch could not resolve an executable; ``lines`` is what rosrun prints."""

    def __init__(self, lines: List[str], exit_code: int, short: str,
                 candidates: List[Path] | None = None) -> None:
        super().__init__(short)
        self.lines = lines
        self.exit_code = exit_code
        self.short = short
        #: several executables of that name: rosrun lets the user pick one
        self.candidates = candidates or []


def _is_executable_file(path: Path) -> bool:
    try:
        st = path.stat()
    except OSError:
        return False
    return stat.S_ISREG(st.st_mode) and bool(st.st_mode & 0o111)


def _libexec_dirs(pkg: str) -> List[Path]:
    """``<prefix>/lib/<pkg>`` for every CMAKE_PREFIX_PATH entry (catkin's devel/install spaces)."""
    dirs = []
    for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        if prefix.strip():
            candidate = Path(prefix) / "lib" / pkg
            if candidate.is_dir():
                dirs.append(candidate)
    return dirs


def _search(root: Path, name: str, skip_build: bool) -> List[Path]:
    """Files called ``name`` below ``root`` (symlinks followed once, like ``find -L``)."""
    found: List[Path] = []
    seen = set()
    for dirpath, dirnames, filenames in os.walk(root, followlinks=True):
        try:
            real = os.path.realpath(dirpath)
        except OSError:
            continue
        if real in seen:  # a symlink loop
            dirnames[:] = []
            continue
        seen.add(real)
        if skip_build and Path(dirpath) == root:
            dirnames[:] = [d for d in dirnames if d != "build"]
        dirnames.sort()
        if name in filenames or name in dirnames:
            found.append(Path(dirpath) / name)
    return found


def builtin_module(pkg: str, executable: str) -> str | None:
    """The module of a built-in node, or None."""
    return BUILTIN_NODES.get(pkg, {}).get(executable)


def _module_exists(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except ImportError:  # a parent package is missing
        return False


def command_for(path: Path) -> List[str]:
    """argv prefix that runs ``path``: Python scripts run under minros's interpreter."""
    try:
        with open(path, "rb") as f:
            first = f.readline(256)
    except OSError:
        first = b""
    if _PYTHON_SHEBANG.match(first):
        return [sys.executable, str(path)]
    return [str(path)]


def resolve_executable(pkg: str, executable: str) -> List[str]:
    """The argv prefix that runs ``executable`` of package ``pkg``; raises ExecutableError."""
    pkg_dir = packages.find_package(pkg)
    module = builtin_module(pkg, executable)
    if module and (pkg_dir is None or packages.is_builtin(pkg_dir)):
        if not _module_exists(module):
            raise ExecutableError(
                [f"[rosrun] {executable} of package {pkg} is not available in this version of minros"],
                3, f"{pkg}/{executable} is not available in this version of minros")
        return [sys.executable, "-m", module]
    if pkg_dir is None:
        raise ExecutableError([f"[rospack] Error: package '{pkg}' not found"], 2,
                              f"package '{pkg}' not found")
    if executable.endswith("/"):
        raise ExecutableError([f"Invalid filename:  {executable}"], 1, f"invalid filename {executable}")
    if "/" in executable:
        absname = pkg_dir / executable
        if not _is_executable_file(absname):
            raise ExecutableError([f"[rosrun] Couldn't find executable named {absname}"], 3,
                                  f"couldn't find executable named {absname}")
        return command_for(absname)
    unique = _executables_in(pkg, pkg_dir, executable)
    if not unique and module and _module_exists(module):
        # the package's sources on ROS_PACKAGE_PATH (rosout's C++, say) have no program: as
        # ROS finds the installed one first, minros's built-in one runs
        return [sys.executable, "-m", module]
    if not unique:
        lines = [f"[rosrun] Couldn't find executable named {executable} below {pkg_dir}"]
        others = _search(pkg_dir, executable, skip_build=False)
        if others:
            lines.append("[rosrun] Found the following, but they're either not files,")
            lines.append("[rosrun] or not executable:")
            lines += [f"[rosrun]   {p}" for p in others]
        raise ExecutableError(lines, 3, f"couldn't find executable named {executable} below {pkg_dir}")
    if len(unique) > 1:
        raise ExecutableError(
            ["[rosrun] You have chosen a non-unique executable, please pick one of the following:"]
            + [f"{i}) {p}" for i, p in enumerate(unique, 1)], 3,
            f"non-unique executable {executable} in package {pkg}: " + ", ".join(map(str, unique)),
            candidates=unique)
    return command_for(unique[0])


def _executables_in(pkg: str, pkg_dir: Path, executable: str) -> List[Path]:
    """Executable files called ``executable`` in ``<prefix>/lib/<pkg>`` folders, then below
    the package folder (``build/`` skipped), each once."""
    candidates: List[Path] = []
    for root in _libexec_dirs(pkg) + [pkg_dir]:
        candidates += [p for p in _search(root, executable, root == pkg_dir) if _is_executable_file(p)]
    return list(dict.fromkeys(candidates))


def find_executables(pkg: str, executable: str) -> List[Path]:
    """The files rosrun would choose among for ``pkg executable`` (roslib.packages.find_node):
    none for a package that is missing or a program minros ships as a module."""
    pkg_dir = packages.find_package(pkg)
    if pkg_dir is None:
        return []
    return _executables_in(pkg, pkg_dir, executable)


def child_environment(env: Dict[str, str] | None = None) -> Dict[str, str]:
    """``env`` with minros's interpreter folder on PATH, so ``#!/usr/bin/env python`` finds it."""
    out = dict(os.environ if env is None else env)
    venv_bin = str(Path(sys.executable).absolute().parent)
    path = out.get("PATH", "")
    if venv_bin not in path.split(os.pathsep):
        out["PATH"] = venv_bin + (os.pathsep + path if path else "")
    return out
