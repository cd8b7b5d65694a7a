"""``minros launch`` / ``roslaunch``: start nodes and parameters from .launch files.

``roslaunch PKG FILE.launch [arg:=value...]`` or ``roslaunch PATH... [arg:=value...]``.
Starts a master when none answers at ROS_MASTER_URI (or ``-p PORT``), prints roslaunch's
summary, and runs until Ctrl-C, a required node's exit, or the exit of every node.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any, List, Tuple

from minros import names, packages
from minros.launch.config import LaunchConfig, LaunchError

LAUNCH_SUFFIXES = (".launch", ".xml", ".test")
#: Launch files of the packages minros ships (turtlesim's multisim.launch), as <pkg>/launch/...
BUILTIN_LAUNCH_DIR = Path(__file__).resolve().parent.parent / "launch" / "share"


def _parser(prog: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog, usage=f"{prog} [options] [package] <filename> [arg_name:=value...]\n"
                         f"       {prog} [options] <filename> [<filename>...] [arg_name:=value...]",
        description="Start nodes and set parameters from roslaunch XML files.")
    parser.add_argument("positional", nargs="*", help=argparse.SUPPRESS)
    parser.add_argument("--files", action="store_true", help="Print list of files loaded by launch file, including launch file itself")
    parser.add_argument("--args", dest="node_args", metavar="NODE_NAME", help="Print command-line arguments for node")
    parser.add_argument("--nodes", action="store_true", help="Print list of node names in launch file")
    parser.add_argument("--find-node", metavar="NODE_NAME", help="Find launch file that node is defined in")
    parser.add_argument("--ros-args", action="store_true", help="Display command-line arguments for this launch file")
    parser.add_argument("--dump-params", action="store_true", help="Dump parameters of all roslaunch files to stdout")
    parser.add_argument("-c", "--child", dest="child_name", help=argparse.SUPPRESS)
    parser.add_argument("--local", action="store_true", help="Do not launch remote nodes (minros never does)")
    parser.add_argument("--screen", action="store_true", help="Force output of all local nodes to screen")
    parser.add_argument("--log", action="store_true", help="Force output of all local nodes to log")
    parser.add_argument("-u", "--server_uri", help=argparse.SUPPRESS)
    parser.add_argument("--run_id", help="run_id of session")
    parser.add_argument("--wait", action="store_true", help="wait for master to start before launching")
    parser.add_argument("-p", "--port", type=int, help="master port. Only valid if master is launched")
    parser.add_argument("--core", action="store_true", help="Launch core services only")
    parser.add_argument("--pid", help="write the roslaunch pid to filename")
    parser.add_argument("-v", action="store_true", dest="verbose", help="verbose printing")
    parser.add_argument("--no-summary", action="store_true", help="hide summary printing")
    parser.add_argument("--disable-title", action="store_true", help="accepted for compatibility")
    parser.add_argument("--skip-log-check", action="store_true", help="accepted for compatibility")
    parser.add_argument("--sigint-timeout", type=float, default=15.0, help="the SIGINT timeout used when killing nodes (in seconds)")
    parser.add_argument("--sigterm-timeout", type=float, default=2.0, help="the SIGTERM timeout used when killing nodes if SIGINT does not stop the node (in seconds)")
    return parser


def resolve_launch_arguments(positional: List[str]) -> Tuple[List[str], List[str]]:
    """Split ``[pkg] file... name:=value...`` into launch file paths and arg assignments."""
    args = [a for a in positional if ":=" in a]
    rest = [a for a in positional if ":=" not in a]
    if not rest:
        return [], args
    if len(rest) == 2 and not os.path.isfile(rest[0]):
        pkg, name = rest
        pkg_dir = packages.find_package(pkg)
        if pkg_dir is not None:
            roots = [pkg_dir]
            if packages.is_builtin(pkg_dir) and (BUILTIN_LAUNCH_DIR / pkg).is_dir():
                roots.append(BUILTIN_LAUNCH_DIR / pkg)
            matches = []
            for root in roots:
                candidate = root / name
                matches += [candidate] if candidate.is_file() else sorted(
                    p for p in root.rglob(Path(name).name) if p.is_file() and not _in_build(p, root))
            if len(matches) == 1:
                return [str(matches[0])], args
            if len(matches) > 1:
                listing = ", ".join(str(m) for m in matches)
                raise LaunchError(f"multiple files named [{name}] in package [{pkg}]: {listing}; "
                                  "please specify full path instead")
        if os.path.isfile(rest[0]) or rest[0].endswith(LAUNCH_SUFFIXES):
            pass  # fall through: maybe two plain file names
        else:
            raise LaunchError(f"[{name}] is neither a launch file in package [{pkg}] nor is [{pkg}] a launch file name")
    for path in rest:
        if not os.path.isfile(path):
            raise LaunchError(f"[{path}] is not a launch file name")
    return rest, args


def _in_build(path: Path, pkg_dir: Path) -> bool:
    try:
        return path.relative_to(pkg_dir).parts[0] == "build"
    except (ValueError, IndexError):
        return False


def load_all(files: List[str], args: List[str]) -> LaunchConfig:
    """Load several launch files into one configuration (later files add to earlier ones)."""
    from minros.launch.loader import Loader

    loader = Loader()
    for path in files:
        loader.load(path, args)
    return loader.config


def main(argv: List[str], prog: str | None = None) -> int:
    prog = prog or "minros launch"
    options = _parser(prog).parse_intermixed_args(argv)
    try:
        return _main(options, prog)
    except LaunchError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 1


def _master_uri(options: argparse.Namespace) -> str:
    from minros.rosenv import get_master_uri, remapped_master

    # as rosgraph.get_master_uri in roslaunch: the first __master:= on the command line beats
    # the environment, and one without a value is an error
    try:
        value = remapped_master(options.positional)
    except ValueError as exc:
        raise LaunchError(str(exc)) from None
    if value is not None:
        if not value.strip():
            raise LaunchError(f"__master remapping argument '__master:={value}' improperly specified")
        value = value.strip()
    uri = get_master_uri(remapped=value)
    if options.port:
        from urllib.parse import urlparse

        host = urlparse(uri).hostname or "localhost"
        uri = f"http://{host}:{options.port}/"
    return uri if uri.endswith("/") else uri + "/"


def _main(options: argparse.Namespace, prog: str) -> int:
    from minros.launch.runner import LaunchRunner, dump_params

    files, args = resolve_launch_arguments(options.positional)
    if options.core:
        config = LaunchConfig()
    elif options.ros_args:
        config = LaunchConfig()  # loaded below with the <arg> tags only
    else:
        if not files:
            print(f"{prog}: error: you must specify at least one input file", file=sys.stderr)
            return 1
        config = load_all(files, args)
    if options.files:
        for path in sorted({os.path.abspath(f) for f in config.files}):  # roslaunch: set order
            print(path)
        return 0
    if options.nodes:
        for node in config.nodes:
            print(node.resolved_name)
        return 0
    if options.find_node:
        resolved = names.script_resolve_name("roslaunch", options.find_node)
        for node in config.nodes:
            if node.resolved_name == resolved:
                print(os.path.abspath(node.filename or ""))
                return 0
        print(f"ERROR: cannot find node named [{options.find_node}]. Run \n\troslaunch --nodes <files>\nto see list of node names.", file=sys.stderr)
        return 1
    if options.ros_args:
        from minros.launch.loader import Loader

        loader = Loader(run_commands=False, args_only=True)
        for path in files:
            loader.load(path, args)
        docs = loader.config.arg_docs
        if not docs:
            print("No arguments.")
        required = sorted(n for n, (_doc, default) in docs.items() if default is None)
        optional = sorted(n for n, (_doc, default) in docs.items() if default is not None)
        if required:
            print("Required Arguments:")
            for name in required:
                print(f"  {name}: {docs[name][0] or 'undocumented'}")
        if optional:
            print("Optional Arguments:")
            for name in optional:
                doc, default = docs[name]
                print(f'  {name} (default "{default}"): {doc or "undocumented"}')
        return 0
    if options.dump_params:
        sys.stdout.write(dump_params(config))
        return 0
    if not options.node_args:
        _add_core_params(config)
    runner = LaunchRunner(config, master_uri=_master_uri(options), screen=options.screen and not options.log,
                          wait_for_master=options.wait, run_id=options.run_id, core_only=options.core,
                          sigint_timeout=options.sigint_timeout, sigterm_timeout=options.sigterm_timeout)
    if options.node_args:
        return _print_node_args(config, runner, options.node_args)
    if options.pid:
        Path(options.pid).write_text(str(os.getpid()))
    if not options.no_summary:
        print(config.summary(), flush=True)
    for warning in config.warnings:
        print(f"WARNING: {warning}", file=sys.stderr, flush=True)
    return runner.run()


def _add_core_params(config: LaunchConfig) -> None:
    """/rosdistro and /rosversion, which roslaunch sets on every launch (from roscore.xml)."""
    try:
        from importlib.metadata import version

        minros_version = version("minros")
    except Exception:  # not installed as a distribution (source tree on sys.path)
        minros_version = "0.0.0"
    for key, value in (("/rosdistro", "noetic\n"), ("/rosversion", minros_version + "\n")):
        config.params.setdefault(key, value)


def _print_node_args(config: LaunchConfig, runner: Any, wanted: str) -> int:
    """``roslaunch --args NODE``: the node's environment and command line, as roslaunch prints
    them (``ROS_NAMESPACE="/g" NAME="value" exe args remaps __name:=n``)."""
    resolved = names.script_resolve_name("roslaunch", wanted)
    matches = [n for n in config.nodes if n.resolved_name == resolved]
    if not matches:
        listing = "\n".join(f" * {n.resolved_name}" for n in config.nodes)
        print(f"ERROR: Cannot find node named [{resolved}] in [{', '.join(config.files[:1])}].\n"
              f"Node names are:\n{listing}", file=sys.stderr)
        return 1
    node = matches[0]
    argv, _cwd = runner.node_command(node, node.resolved_name.lstrip("/"))
    wanted_env = {"ROS_MASTER_URI": runner.master_uri}
    if node.namespace != "/":
        wanted_env["ROS_NAMESPACE"] = node.namespace.rstrip("/")
    wanted_env.update(node.env_args)
    # like roslaunch, only what differs from the current environment
    env = [f'{k}="{v}"' for k, v in wanted_env.items() if os.environ.get(k) != v]
    print(" ".join(env + [a for a in argv if not a.startswith("__log:=")]))
    return 0
