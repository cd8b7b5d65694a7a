"""``minros ws`` and the catkin names: ``catkin_init_workspace``, ``catkin_create_pkg``, ``catkin_make``.

``minros ws init [SRC]``, ``minros ws create_pkg NAME [DEPS...]``, ``minros ws make [-C WS]``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import List


def _init(argv: List[str], prog: str) -> int:
    from minros.workspace.catkin import init_workspace

    parser = argparse.ArgumentParser(
        prog=prog, description="Initializes a catkin workspace by creating a top-level CMakeLists.txt.")
    parser.add_argument("workspace", nargs="?", default=".",
                        help="The path to an existing folder (default: .)")
    args = parser.parse_args(argv)
    init_workspace(Path(args.workspace))
    return 0


def _create_pkg(argv: List[str], prog: str) -> int:
    from minros.workspace.catkin import create_package

    parser = argparse.ArgumentParser(
        prog=prog, description="Creates a new catkin package")
    parser.add_argument("name", help="The name for the package")
    parser.add_argument("dependencies", nargs="*", help="Catkin package Dependencies")
    parser.add_argument("-s", "--sys-deps", nargs="*", default=[], help="System Dependencies")
    parser.add_argument("-b", "--boost-comps", nargs="*", default=[], help="Boost Components")
    parser.add_argument("-V", "--pkg_version", default="0.0.0", help="Initial Package version")
    parser.add_argument("-D", "--description", help="Description")
    parser.add_argument("-l", "--license", default="TODO", help="Name for License, (e.g. BSD, MIT, GPLv3...)")
    parser.add_argument("-a", "--author", action="append", default=[], help="A single author, may be used multiple times")
    parser.add_argument("-m", "--maintainer", help="A single maintainer")
    parser.add_argument("--rosdistro", help="The ROS distro (ignored: minros is noetic)")
    parser.add_argument("-p", "--path", default=".", help="The path in which to create the package")
    args = parser.parse_args(argv)
    create_package(args.name, args.dependencies + args.sys_deps, Path(args.path),
                   version=args.pkg_version, description=args.description, license_=args.license,
                   maintainer=args.maintainer, authors=args.author,
                   warn=lambda line: print(line, file=sys.stderr))
    return 0


def _make(argv: List[str], prog: str) -> int:
    from minros.workspace.catkin import make_workspace

    parser = argparse.ArgumentParser(
        prog=prog, description="Builds a catkin workspace: devel/setup.bash, message modules.")
    parser.add_argument("-C", "--directory", default=".", help="The base path of the workspace (default '.')")
    parser.add_argument("-j", "--jobs", type=int, help="accepted for compatibility (nothing to compile)")
    parser.add_argument("-l", "--load-average", help="accepted for compatibility")
    parser.add_argument("--source", help="The path to the source space (default 'workspace_base/src')")
    parser.add_argument("targets", nargs="*", help="accepted for compatibility (e.g. 'install')")
    args, _unknown = parser.parse_known_args(argv)  # -DCMAKE_... etc. have no meaning here
    make_workspace(Path(args.directory), jobs=args.jobs)
    return 0


_TOOLS = {"init": ("catkin_init_workspace", _init), "create_pkg": ("catkin_create_pkg", _create_pkg),
          "make": ("catkin_make", _make)}

_USAGE = "usage: {prog} {{init,create_pkg,make}} ..."

_HELP = """\
{usage}

Catkin workspaces as the ROS tutorials build them. Nothing is compiled: the messages and
services of your packages (msg/*.msg, srv/*.srv) are generated when a script imports them.

commands:
  init [SRC]                 make SRC (default .) a workspace's source space: its top-level
                             CMakeLists.txt (catkin_init_workspace)
  create_pkg NAME [DEPS...]  create package NAME: package.xml, CMakeLists.txt, src/
                             (catkin_create_pkg)
  make [-C WS]               build workspace WS (default .): devel/setup.bash, which puts its
                             packages on ROS_PACKAGE_PATH, PATH and PYTHONPATH (catkin_make)

'{prog} COMMAND --help' gives the options of a command. A workspace, from the start:

  mkdir -p ~/catkin_ws/src && cd ~/catkin_ws/src
  {prog} init
  {prog} create_pkg my_package rospy std_msgs
  cd ~/catkin_ws && {prog} make && source devel/setup.bash
  rosrun my_package my_script.py"""


def main(argv: List[str], prog: str | None = None) -> int:
    from minros.workspace.catkin import WorkspaceError

    prog = prog or "minros ws"
    if not argv or argv[0] not in _TOOLS:
        usage = _USAGE.format(prog=prog)
        if argv and argv[0] in ("-h", "--help", "help"):
            print(_HELP.format(usage=usage, prog=prog))
            return 0
        what = f"unknown command '{argv[0]}'" if argv else "a command is needed"
        print(f"{usage}\n{prog}: error: {what} (init, create_pkg or make; "
              f"'{prog} --help' explains them)", file=sys.stderr)
        return 2
    ros_name, tool = _TOOLS[argv[0]]
    # called as `catkin_make`, prog is the ROS name; as `minros ws make`, the sub-command
    name = prog if prog.startswith("catkin") else f"{prog} {argv[0]}"
    try:
        return tool(argv[1:], name)
    except WorkspaceError as exc:
        print(f"{name}: error: {exc}", file=sys.stderr)
        return 1
