"""roslaunch's helper modules over minros's loader and runner: node_args (the command line a
node would get), arg_dump (a launch file's arguments), param_dump (its parameters as YAML),
netapi (the roslaunch processes a master knows), rlutil.check_roslaunch and depends (the
packages a launch file needs)."""

from __future__ import annotations

import os
import sys
import xmlrpc.client
from typing import Any, Dict, List, Optional, Sequence, Tuple

from minros import names, packages, rosenv
from minros.launch.config import LaunchConfig, LaunchError
from minros.launch.loader import Loader
from minros.launch.rosmodel import (
    RLException,
    ROSLaunchConfig,
    XmlLoader,
    load_config_default,
    local_machine,
    setup_env,
)
from minros.launch.runner import LaunchRunner

# ---------------------------------------------------------------------------------------------
# roslaunch.node_args


class NodeParamsException(Exception):
    """A node's parameters cannot be read."""


def _resolved_name(node: Any) -> Optional[str]:
    if not node.name:
        return None
    return node.name if node.name.startswith("$") else names.ns_join(node.namespace, node.name)


def get_node_list(config: Any) -> List[str]:
    """The resolved names of a config's nodes and tests."""
    found = [_resolved_name(n) for n in list(config.nodes) + list(config.tests)]
    return [n for n in found if n]


def _load(roslaunch_files: Sequence[str]) -> ROSLaunchConfig:
    return load_config_default(roslaunch_files, None, loader=XmlLoader(resolve_anon=False),
                               verbose=False, assign_machines=False)


def _find_node(node_name: str, roslaunch_files: Sequence[str], config: Any) -> Any:
    found = [n for n in list(config.nodes) + list(config.tests) if _resolved_name(n) == node_name]
    if not found:
        listing = "\n".join(f" * {x}" for x in get_node_list(config))
        raise RLException(f"ERROR: Cannot find node named [{node_name}] in "
                          f"[{', '.join(roslaunch_files)}].\nNode names are:\n{listing}")
    if len(found) > 1:
        raise RLException(f"ERROR: multiple nodes named [{node_name}] in "
                          f"[{', '.join(roslaunch_files)}].\nPlease fix the launch files as "
                          "duplicate names are not allowed.")
    return found[0]


def create_local_process_args(node: Any, machine: Any, env: Optional[Dict[str, str]] = None) -> List[str]:
    """The command line of ``node`` (its executable found as rosrun finds it)."""
    if not node.name:
        raise ValueError("node name must be defined")
    runner = LaunchRunner(LaunchConfig(), master_uri=rosenv.get_master_uri(), env=env)
    try:
        argv, _cwd = runner.node_command(node, node.name)
    except LaunchError as exc:
        raise RLException(str(exc)) from None
    return argv


def get_node_args(node_name: str, roslaunch_files: Sequence[str]) -> List[str]:
    """``KEY="value"`` for each environment variable the node's launch changes, then its
    command line."""
    config = _load(roslaunch_files)
    if not node_name.startswith("$"):
        node_name = names.script_resolve_name("roslaunch", node_name)
    node = _find_node(node_name, roslaunch_files, config)
    env = setup_env(node, local_machine(), rosenv.get_master_uri())
    changed = {k: v for k, v in env.items() if os.environ.get(k) != v}
    return [f'{k}="{v}"' for k, v in changed.items()] + create_local_process_args(node, local_machine())


def print_node_list(roslaunch_files: Sequence[str]) -> None:
    try:
        print("\n".join(get_node_list(_load(roslaunch_files))))
    except RLException as exc:
        print(str(exc), file=sys.stderr)
        sys.exit(1)


def print_node_args(node_name: str, roslaunch_files: Sequence[str]) -> None:
    try:
        print(" ".join(get_node_args(node_name, roslaunch_files)))
    except RLException as exc:
        print(str(exc), file=sys.stderr)
        sys.exit(1)


def print_node_filename(node_name: str, roslaunch_files: Sequence[str]) -> None:
    try:
        node_name = names.script_resolve_name("roslaunch", node_name)
        print(_find_node(node_name, roslaunch_files, _load(roslaunch_files)).filename)
    except RLException as exc:
        print(str(exc), file=sys.stderr)
        sys.exit(1)


# ---------------------------------------------------------------------------------------------
# roslaunch.arg_dump and roslaunch.param_dump

def get_args(roslaunch_files: Sequence[str]) -> Dict[str, Tuple[Optional[str], Optional[str]]]:
    """``{arg: (doc, default)}`` of the first launch file's declared arguments."""
    docs: Dict[str, Tuple[Optional[str], Optional[str]]] = {}
    for path in roslaunch_files:
        try:
            docs.update(Loader(args_only=True, check_machines=False).load(path).arg_docs)
        except LaunchError as exc:
            raise RLException(exc.message) from None
    return docs


def dump_args(roslaunch_files: Sequence[str]) -> None:
    """Print the arguments, required ones first (roslaunch --ros-args)."""
    try:
        args = get_args(roslaunch_files)
    except RLException as exc:
        print(str(exc), file=sys.stderr)
        sys.exit(1)
    if not args:
        print("No arguments.")
        return
    required = sorted((n, doc or "undocumented") for n, (doc, default) in args.items() if not default)
    optional = sorted((n, doc or "undocumented", default) for n, (doc, default) in args.items() if default)
    if required:
        print("Required Arguments:")
        for name, doc in required:
            print(f"  {name}: {doc}")
    if optional:
        print("Optional Arguments:")
        for name, doc, default in optional:
            print(f'  {name} (default "{default}"): {doc}')


def dump_params(files: Sequence[str]) -> bool:
    """Print the files' parameters as YAML; False (and a message) when one does not load."""
    import yaml

    config = ROSLaunchConfig()
    loader = XmlLoader()
    for f in files:
        try:
            loader.load(f, config, verbose=False)
        except Exception as exc:
            sys.stderr.write(f"Unable to load file {f}: {exc}")
            return False
    sys.stdout.write(yaml.safe_dump({str(k): v.value for k, v in config.params.items()}) + "\n")
    return True


# ---------------------------------------------------------------------------------------------
# roslaunch.netapi

def get_roslaunch_uris() -> Optional[List[str]]:
    """The XML-RPC URIs of the roslaunch processes registered under /roslaunch/uris, or None
    when the master cannot be asked."""
    from minros.tools.master import Master, MasterException

    try:
        return list(Master("/roslaunch_netapi").getParam("/roslaunch/uris").values())
    except (MasterException, OSError, AttributeError):
        return None


class NetProcess:
    """A process one roslaunch runs."""

    def __init__(self, name: str, respawn_count: int, is_alive: bool, roslaunch_uri: str) -> None:
        self.is_alive = is_alive
        self.respawn_count = respawn_count
        self.name = name
        self.roslaunch_uri = roslaunch_uri
        self.machine, _ = rosenv.parse_http_host_and_port(roslaunch_uri)


def list_processes(roslaunch_uris: Optional[Sequence[str]] = None) -> List[NetProcess]:
    """The processes of every roslaunch (those answering within 5 s)."""
    uris = list(roslaunch_uris or get_roslaunch_uris() or [])
    procs: List[NetProcess] = []
    for uri in uris:
        from minros.tools.master import call_node

        try:
            code, _msg, (active, dead) = call_node(uri, "list_processes")
        except (OSError, ValueError, TypeError, xmlrpc.client.Error):
            continue
        if code == 1:
            procs += [NetProcess(a[0], a[1], True, uri) for a in active]
            procs += [NetProcess(d[0], d[1], False, uri) for d in dead]
    return procs


# ---------------------------------------------------------------------------------------------
# roslaunch.rlutil.check_roslaunch and roslaunch.depends

class RoslaunchDepsException(Exception):
    """A launch file's dependencies cannot be computed."""


def roslaunch_deps(files: Sequence[str], verbose: bool = False, use_test_depends: bool = False,
                   ignore_unset_args: bool = False) -> Tuple[Optional[str], Dict[str, Any], Dict[str, List[str]]]:
    """``(base package, {file: packages its nodes use}, {package: packages it uses but does
    not declare})`` of launch files (all in one package)."""
    base_pkgs = {packages_of_file(f) for f in files}
    if len(base_pkgs) > 1:
        raise RoslaunchDepsException("roslaunch files must be in the same package: "
                                     + ", ".join(sorted(str(p) for p in base_pkgs)))
    base_pkg = base_pkgs.pop() if base_pkgs else None
    file_deps: Dict[str, Any] = {}
    for f in files:
        try:
            loaded = Loader(check_machines=False).load(f)
        except LaunchError as exc:
            raise RoslaunchDepsException(str(exc)) from None
        file_deps[f] = sorted({n.package for n in loaded.nodes + loaded.tests})
    missing: Dict[str, List[str]] = {}
    if base_pkg:
        declared = set(packages.dependency_query(base_pkg))
        used = {p for deps in file_deps.values() for p in deps}
        absent = sorted(used - declared - {base_pkg})
        if absent:
            missing[base_pkg] = absent
    return base_pkg, file_deps, missing


def packages_of_file(path: str) -> Optional[str]:
    """The package a file is in."""
    return packages.get_dir_pkg(os.path.dirname(os.path.abspath(path)))[1]


def check_roslaunch(f: str, use_test_depends: bool = False,
                    ignore_unset_args: bool = False) -> Optional[str]:
    """Problems of launch file ``f`` as one text (None when there are none): it must load, and
    the packages its nodes use must be installed. With ``ignore_unset_args``, arguments that
    have no value are given one."""
    argv: List[str] = []
    if ignore_unset_args:
        try:
            # a value every use accepts (if=, a number, a name): the file is only checked
            argv = [f"{n}:=0" for n, (_doc, default) in get_args([f]).items() if default is None]
        except RLException:
            argv = []
    try:
        loaded = Loader(check_machines=False).load(f, argv)
    except LaunchError as exc:
        return f"[{f}]:\n\t{exc.message}"
    errors = []
    for node in loaded.nodes + loaded.tests:
        if packages.find_package(node.package) is None:
            errors.append(f"[{f}]:\n\tcannot find package [{node.package}] for node [{node.name}]")
    return "\n".join(errors) or None
