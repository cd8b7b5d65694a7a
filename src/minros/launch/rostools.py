"""roslaunch's helper modules over minros's loader and runner: node_args (the command line a
node would get), arg_dump (a launch file's arguments), param_dump (its parameters as YAML),
netapi (the roslaunch processes a master knows), rlutil.check_roslaunch and depends (the
packages a launch file needs)."""

from __future__ import annotations

import os
import sys
import xmlrpc.client
from typing import Any, Dict, List, Optional, Sequence, Tuple
from xml.etree import ElementTree

import rospkg

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
from minros.wire.rosapi import RemoteError, unwrap

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
    """The command line of ``node``: its launch-prefix, its executable (found as rosrun finds
    it), its args (substitution args resolved), its remappings and ``__name:=``.
    NodeParamsException when the executable cannot be found."""
    import copy

    from minros.launch.rosmodel import resolve_args

    if not node.name:
        raise ValueError("node name must be defined")
    context: Dict[str, Any] = {} if env is None else {"env": env}
    resolved = copy.copy(node)
    resolved.name = resolve_args(node.name, context=context)
    resolved.args = resolve_args(node.args, context=context) or ""
    runner = LaunchRunner(LaunchConfig(), master_uri=rosenv.get_master_uri(), env=env)
    try:
        argv, _cwd = runner.node_command(resolved, resolved.name)
    except LaunchError as exc:  # the cause alone: callers say which node could not launch
        prefix = f"cannot launch node of type [{node.package}/{node.type}]: "
        message = exc.message[len(prefix):] if exc.message.startswith(prefix) else exc.message
        raise NodeParamsException(message) from None
    node.name = resolved.name
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
        from minros.tools.master import TOOL_TIMEOUT
        from minros.wire.xmlrpc import ServerProxy

        # roslaunch's process API (no node API: no caller id), one call per roslaunch
        try:
            with ServerProxy(uri, timeout=TOOL_TIMEOUT) as launcher:
                active, dead = unwrap(launcher.list_processes())
        except (OSError, ValueError, TypeError, xmlrpc.client.Error, RemoteError):
            continue
        procs += [NetProcess(a[0], a[1], True, uri) for a in active]
        procs += [NetProcess(d[0], d[1], False, uri) for d in dead]
    return procs


# ---------------------------------------------------------------------------------------------
# roslaunch.rlutil.check_roslaunch and roslaunch.depends

class RoslaunchDepsException(Exception):
    """A launch file's dependencies cannot be computed."""


class RoslaunchDeps:
    """What one launch file uses: ``nodes`` as ``(package, type)``, the files it includes, and
    the packages of both (roslaunch.depends.RoslaunchDeps)."""

    def __init__(self, nodes: Optional[List[Tuple[str, str]]] = None,
                 includes: Optional[List[str]] = None, pkgs: Optional[List[str]] = None) -> None:
        self.nodes = [] if nodes is None else nodes
        self.includes = [] if includes is None else includes
        self.pkgs = [] if pkgs is None else pkgs

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, RoslaunchDeps):
            return False
        return ((set(self.nodes), set(self.includes), set(self.pkgs))
                == (set(other.nodes), set(other.includes), set(other.pkgs)))

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"nodes: {self.nodes}\nincludes: {self.includes}\npkgs: {self.pkgs}"

    __str__ = __repr__


def packages_of_file(path: str) -> Optional[str]:
    """The package a file is in."""
    return packages.get_dir_pkg(os.path.dirname(os.path.abspath(path)))[1]


def _attr(el: Any, name: str, context: Dict[str, Any]) -> str:
    from minros.launch.rosmodel import resolve_args

    try:
        return resolve_args(el.attrib[name], context)  # type: ignore[return-value]
    except KeyError as exc:
        xml = ElementTree.tostring(el, encoding="unicode").strip()
        raise RoslaunchDepsException(f"Cannot load roslaunch <{el.tag}> tag: missing required "
                                     f"attribute {exc}.\nXML is {xml}") from None


def _arg_value(el: Any, context: Dict[str, Any]) -> str:
    from minros.launch.rosmodel import resolve_args

    name = el.attrib["name"]
    if "value" in el.attrib:
        return resolve_args(el.attrib["value"], context)  # type: ignore[return-value]
    if name in context["arg"]:
        return context["arg"][name]
    if "default" in el.attrib:
        return resolve_args(el.attrib["default"], context)  # type: ignore[return-value]
    raise RoslaunchDepsException(f"No value for arg [{name}]")


def _included(el: Any, context: Dict[str, Any]) -> bool:
    """The element's if= / unless= (one of them, if first) allows it."""
    from minros.launch.rosmodel import resolve_args
    from minros.launch.substitution import convert_value

    if "if" in el.attrib:
        return bool(convert_value(resolve_args(el.attrib["if"], context) or "", "bool"))
    if "unless" in el.attrib:
        return not convert_value(resolve_args(el.attrib["unless"], context) or "", "bool")
    return True


def _launch_element(path: str) -> Any:
    """The <launch> element of a file (None when it has none); OSError, ParseError pass up."""
    root = ElementTree.parse(path).getroot()
    return root if root.tag == "launch" else next(root.iter("launch"), None)


def _walk(elements: Sequence[Any], launch_file: str, file_deps: Dict[str, RoslaunchDeps],
          verbose: bool, context: Dict[str, Any]) -> None:
    """roslaunch.depends' walk: groups, args, includes (recursively, each file its own entry)
    and the packages of nodes and tests, honouring if/unless; nothing is loaded or run."""
    context["filename"] = os.path.abspath(launch_file)
    own_pkg = packages_of_file(launch_file)
    deps = file_deps[launch_file]
    for el in elements:
        if not _included(el, context):
            continue
        if el.tag == "group":
            _walk(list(el), launch_file, file_deps, verbose, context)
        elif el.tag == "arg":
            context["arg"][el.attrib["name"]] = _arg_value(el, context)
        elif el.tag == "include":
            sub_file = _attr(el, "file", context)
            if sub_file == "":  # an include left empty on purpose (inside a condition)
                if verbose:
                    print(f"Empty <include> in {launch_file}. Skipping <include> of {el.attrib['file']}")
                continue
            if verbose:
                print(f"processing included launch {sub_file}")
            sub_pkg = packages_of_file(sub_file)
            if sub_pkg is None:
                print(f"ERROR: cannot determine package for [{sub_file}]", file=sys.stderr)
            if sub_file not in deps.includes:
                deps.includes.append(sub_file)
            if own_pkg != sub_pkg:
                deps.pkgs.append(sub_pkg)  # type: ignore[arg-type]
            file_deps[sub_file] = RoslaunchDeps()
            try:
                launch = _launch_element(sub_file)
            except (OSError, ElementTree.ParseError):
                raise RoslaunchDepsException(f"Cannot load roslaunch include '{sub_file}' in "
                                             f"'{launch_file}'") from None
            if launch is None:
                print(f"ERROR: {sub_file} is not a valid roslaunch file", file=sys.stderr)
                continue
            sub_context: Dict[str, Any] = {"arg": {}}
            for child in el:
                if child.tag == "arg" and _included(child, context):
                    sub_context["arg"][child.attrib["name"]] = _arg_value(child, context)
            if "pass_all_args" in el.attrib:  # present at all, as roslaunch.depends reads it
                context["arg"].update(sub_context["arg"])
                sub_context["arg"] = context["arg"]
            _walk(list(launch), sub_file, file_deps, verbose, sub_context)
        elif el.tag in ("node", "test"):
            pkg, node_type = _attr(el, "pkg", context), _attr(el, "type", context)
            if (pkg, node_type) not in deps.nodes:
                deps.nodes.append((pkg, node_type))
            if pkg not in deps.pkgs:
                deps.pkgs.append(pkg)


def parse_launch(launch_file: str, file_deps: Dict[str, RoslaunchDeps], verbose: bool) -> None:
    """Add ``launch_file`` (and what it includes) to ``file_deps``; arguments come from the
    command line (``name:=value``), as roslaunch-deps reads them."""
    if verbose:
        print(f"processing launch {launch_file}")
    try:
        launch = _launch_element(launch_file)
    except (OSError, ElementTree.ParseError):
        launch = None
    if launch is None:
        raise RoslaunchDepsException(f"invalid XML in {launch_file}")
    file_deps[launch_file] = RoslaunchDeps()
    context = {"arg": names.load_mappings(sys.argv)}
    _walk(list(launch), launch_file, file_deps, verbose, context)


rl_file_deps = parse_launch


def declared_run_depends(pkg: str, use_test_depends: bool = False) -> set:
    """The packages ``pkg`` declares it needs at run time (with its test dependencies when
    asked; a rosbuild manifest's every <depend>)."""
    folder = packages.find_package(pkg)
    if folder is None:
        raise rospkg.ResourceNotFound(pkg)
    if (folder / "package.xml").is_file():
        from catkin_pkg.package import parse_package

        parsed = parse_package(str(folder))
        found = {d.name for d in parsed.run_depends}
        if use_test_depends:
            found |= {d.name for d in parsed.test_depends}
        return found
    return {d.package for d in packages.parse_manifest_file(str(folder / "manifest.xml")).depends}


def calculate_missing(base_pkg: Optional[str], missing: Dict[str, set],
                      file_deps: Dict[str, RoslaunchDeps],
                      use_test_depends: bool = False) -> Dict[str, set]:
    """Add to ``missing`` the packages each launch file uses that its package does not
    declare."""
    for launch_file, deps in file_deps.items():
        pkg = packages_of_file(launch_file)
        if pkg is None:
            print(f"ERROR: cannot determine package for [{launch_file}]", file=sys.stderr)
            continue
        declared = declared_run_depends(pkg, use_test_depends) | {pkg}
        missing.setdefault(pkg, set()).update(set(deps.pkgs) - declared)
    return missing


def roslaunch_deps(files: Sequence[str], verbose: bool = False, use_test_depends: bool = False,
                   ignore_unset_args: bool = False) -> Tuple[Optional[str], Dict[str, RoslaunchDeps], Dict[str, set]]:
    """``(package of the files, {file: RoslaunchDeps}, {package: packages used but not
    declared})``; the files must be in one package. With ``ignore_unset_args``, an arg without
    a value ends a file's walk instead of failing."""
    file_deps: Dict[str, RoslaunchDeps] = {}
    missing: Dict[str, set] = {}
    base_pkg = None
    for launch_file in files:
        if not os.path.exists(launch_file):
            raise RoslaunchDepsException(f"roslaunch file [{launch_file}] does not exist")
        pkg = packages_of_file(launch_file)
        if base_pkg and pkg != base_pkg:
            raise RoslaunchDepsException(f"roslaunch files must be in the same package: {base_pkg} vs. {pkg}")
        base_pkg = pkg
        try:
            parse_launch(launch_file, file_deps, verbose)
        except RoslaunchDepsException as exc:
            if not (ignore_unset_args and "No value for arg" in str(exc)):
                raise
    calculate_missing(base_pkg, missing, file_deps, use_test_depends=use_test_depends)
    return base_pkg, file_deps, missing


def print_deps(base_pkg: Optional[str], file_deps: Dict[str, RoslaunchDeps], verbose: bool) -> None:
    if verbose:
        for f, deps in file_deps.items():
            for p, t in deps.nodes:
                print(f"{p} [{p}/{t}]")
            pkg = packages_of_file(f)
            if pkg is None:
                print(f"ERROR: cannot determine package for [{f}]", file=sys.stderr)
            else:
                print(f"{pkg} [{f}]")
        print("-" * 80)
    used = dict.fromkeys(p for deps in file_deps.values() for p in deps.pkgs)
    print(" ".join(str(p) for p in used))  # one line, space-separated, for rosmake


def roslaunch_deps_main(argv: Sequence[str] = sys.argv) -> None:
    """roslaunch-deps: the packages launch files use, with --warn those their package does not
    declare."""
    from optparse import OptionParser

    parser = OptionParser(usage="usage: %prog [options] <file(s)...>", prog="roslaunch-deps")
    parser.add_option("--verbose", "-v", action="store_true", dest="verbose", default=False,
                      help="Verbose output")
    parser.add_option("--warn", "-w", action="store_true", dest="warn", default=False,
                      help="Warn about missing manifest dependencies")
    options, args = parser.parse_args(list(argv[1:]))
    if not args:
        parser.error("please specify a launch file")
    files = [a for a in args if os.path.exists(a)]
    absent = [a for a in args if not os.path.exists(a)]
    if absent:
        parser.error(f"cannot locate {','.join(absent)}")
    try:
        base_pkg, file_deps, missing = roslaunch_deps(files, verbose=options.verbose)
    except (RoslaunchDepsException, rospkg.ResourceNotFound) as exc:
        print(str(exc), file=sys.stderr)
        sys.exit(1)
    if options.warn:
        print("Dependencies:")
    print_deps(base_pkg, file_deps, options.verbose)
    if options.warn:
        print("\nMissing declarations:")
        for pkg, miss in missing.items():
            if miss:
                print(f"{pkg}/manifest.xml:")
                for m in miss:
                    print(f'  <depend package="{m}" />')


def check_roslaunch(f: str, use_test_depends: bool = False,
                    ignore_unset_args: bool = False) -> Optional[str]:
    """Problems of launch file ``f`` as one text (None when there are none), as roslaunch's
    rlutil.check_roslaunch finds them: it must load; its package must declare the packages it
    uses (else the packages that package depends on must); those packages and their programs
    must be installed; the config must hold no errors."""
    from minros.launch.rosmodel import ArgException, printerrlog
    from minros.workspace.executables import find_executables

    try:
        config = load_config_default([f], rosenv.DEFAULT_MASTER_PORT, verbose=False,
                                     ignore_unset_args=ignore_unset_args)
    except RLException as exc:
        return str(exc)
    errors: List[str] = []
    try:
        _base, file_deps, missing = roslaunch_deps([f], use_test_depends=use_test_depends,
                                                   ignore_unset_args=ignore_unset_args)
    except rospkg.ResourceNotFound as exc:
        errors.append(f"Could not find package [{exc}] included from [{f}]")
        file_deps, missing = {}, {}
    except ArgException as exc:
        errors.append(f"Could not resolve arg [{exc}] in [{f}]")
        file_deps, missing = {}, {}
    except RoslaunchDepsException as exc:
        return str(exc)
    for pkg, miss in missing.items():
        provided: set = set()
        try:
            for dep_file in file_deps:
                provided.update(packages.dependency_query(packages_of_file(dep_file) or "", direct=True))
            unprovided = set(miss) - provided
        except Exception as exc:  # noqa: BLE001 - roslaunch prints it and counts all as missing
            print(exc, file=sys.stderr)
            unprovided = set(miss) or {""}
        if unprovided:
            text = f"Missing package dependencies: {pkg}/package.xml: {', '.join(sorted(miss))}"
            printerrlog(text)
            errors.append(text)
        elif miss:
            printerrlog(f"Missing package dependencies: {pkg}/package.xml: {', '.join(sorted(miss))} "
                        "(notify upstream maintainer)")
    nodes = [n for deps in file_deps.values() for n in deps.nodes]
    for pkg, node_type in nodes:
        if packages.find_package(pkg) is None:
            errors.append(f"cannot find package [{pkg}] for node [{node_type}]")
    for pkg, node_type in nodes:
        try:
            if not find_executables(pkg, node_type):
                errors.append(f"cannot find node [{node_type}] in package [{pkg}]")
        except Exception as exc:  # noqa: BLE001
            errors.append(f"unable to find node [{pkg}/{node_type}]: {exc}")
    errors.extend(f"ROSLaunch config error: {e}" for e in config.config_errors)
    return "\n".join(errors) or None
