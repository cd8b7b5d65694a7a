"""``minros wtf`` / ``roswtf``: what is wrong with this ROS setup and the graph running now.

    roswtf [--offline] [--no-plugins] [--all] [FILE.launch ...]

Static checks read the environment (ROS_MASTER_URI, ROS_PACKAGE_PATH, PYTHONPATH, ROS_HOME,
ROS_LOG_DIR, ROS_HOSTNAME, ROS_IP, the host name) and the given launch files (they must
load; no two nodes of one name; every package they name installed). Online checks, when the
master answers, read the graph: the master's system state, then every node's bus info (its
connections), and report subscriptions with no publisher, connections the master does not
expect or expected ones that are missing, nodes that do not answer, services that do not
answer a probe, and /use_sim_time without a /clock publisher. Every call to the master or a
node is bounded. The rules, texts and report are roswtf's (WtfContext, warning_rule,
error_rule, print_results); roswtf's plugins and its package, stack, rosdep and pip checks
of a source installation are not run.
"""

from __future__ import annotations

import os
import socket
import sys
import threading
import time
from os.path import isdir, isfile
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple
from urllib.parse import urlparse

from minros import packages, rosenv
from minros.tools.master import Master, MasterException
from minros.wire.rosapi import RemoteError
from minros.wire.slaveapi import SlaveClient

# ---------------------------------------------------------------------------------------------
# the model (roswtf.model, roswtf.context, roswtf.rules)


class WtfException(Exception):
    """roswtf cannot go on (the master went away mid-check)."""


class WtfError:
    """An error found: the message shown, its format, the rule's answer."""

    def __init__(self, msg: str, format_msg: Optional[str] = None, return_val: Any = None) -> None:
        self.msg = msg
        self.format_msg = msg if format_msg is None else format_msg
        self.return_val = True if return_val is None else return_val


class WtfWarning(WtfError):
    """A warning found (something that is sometimes at fault)."""


class WtfContext:
    """What roswtf checks and what it found."""

    __slots__ = ["pkg", "pkg_dir", "pkgs", "stack", "stack_dir", "stacks", "launch_files",
                 "launch_file_pkgs", "system_state", "service_providers", "topics", "services",
                 "nodes", "uri_node_map", "expected_edges", "actual_edges",
                 "unconnected_subscriptions", "use_sim_time", "warnings", "errors", "rules",
                 "ros_root", "ros_package_path", "pythonpath", "ros_master_uri", "env",
                 "roslaunch_uris", "launch_configs"]

    def __init__(self) -> None:
        for name in self.__slots__:
            setattr(self, name, None)
        self.pkgs, self.stacks, self.launch_files, self.launch_file_pkgs = [], [], [], []
        self.topics, self.services, self.nodes, self.service_providers = [], [], [], []
        self.uri_node_map: Dict[str, str] = {}
        self.expected_edges: List[Tuple[str, str, str]] = []
        self.actual_edges: List[Tuple[str, str, str]] = []
        self.unconnected_subscriptions: Dict[str, List[str]] = {}
        self.use_sim_time = False
        self.warnings: List[WtfWarning] = []
        self.errors: List[WtfError] = []
        self.launch_configs: List[Any] = []

    def as_dictionary(self) -> Dict[str, Any]:
        """The context's fields, for the rules' message formats (``%(ros_master_uri)s``)."""
        return {name: getattr(self, name) for name in self.__slots__}

    @staticmethod
    def from_env(env: Optional[Dict[str, str]] = None) -> WtfContext:
        ctx = WtfContext()
        _load_env(ctx, os.environ if env is None else env)
        return ctx

    @staticmethod
    def from_roslaunch(roslaunch_files: Sequence[str],
                       env: Optional[Dict[str, str]] = None) -> WtfContext:
        ctx = WtfContext.from_env(env)
        ctx.launch_files = list(roslaunch_files)
        from minros.launch.config import LaunchError
        from minros.launch.loader import load_launch

        for path in roslaunch_files:
            try:
                ctx.launch_configs.append(load_launch(path))
            except (LaunchError, OSError) as exc:
                raise WtfException(f"Unable to load roslaunch file [{path}]: {exc}") from None
        ctx.launch_file_pkgs = sorted({n.package for c in ctx.launch_configs for n in c.nodes})
        return ctx

    @staticmethod
    def from_package(pkg: str, env: Optional[Dict[str, str]] = None) -> WtfContext:
        ctx = WtfContext.from_env(env)
        ctx.pkg = pkg
        ctx.pkg_dir = packages.get_pkg_dir(pkg, required=False)
        ctx.pkgs = [pkg]
        return ctx


def _load_env(ctx: WtfContext, env: Any) -> None:
    ctx.env = env
    ctx.ros_root = env.get("ROS_ROOT")
    ctx.ros_package_path = env.get("ROS_PACKAGE_PATH")
    ctx.pythonpath = env.get("PYTHONPATH")
    ctx.ros_master_uri = rosenv.get_master_uri(env, check=False)  # its own rule reports it


Rule = Tuple[Callable[[WtfContext], Any], str]


def _check_rule(rule: Rule, ret: Any, ctx: WtfContext, found: List[Any], level: type) -> None:
    """A rule's non-empty answer becomes one finding: its format filled from the context,
    then the answer (a list as `` * item`` lines, a string appended)."""
    if not ret:
        return
    fields = ctx.as_dictionary()
    fmt = rule[1]
    if isinstance(ret, (list, tuple)):
        found.append(level(fmt % fields + "\n" + "\n".join(f" * {r}" for r in ret) + "\n", fmt, ret))
    elif isinstance(ret, str):
        found.append(level(fmt % fields + ret % fields, fmt, ret))
    else:
        found.append(level(fmt % fields, fmt, ret))


def warning_rule(rule: Rule, ret: Any, ctx: WtfContext) -> None:
    _check_rule(rule, ret, ctx, ctx.warnings, WtfWarning)


def error_rule(rule: Rule, ret: Any, ctx: WtfContext) -> None:
    _check_rule(rule, ret, ctx, ctx.errors, WtfError)


# ---------------------------------------------------------------------------------------------
# environment (roswtf.environment) and network (roswtf.network)

def paths(path: Optional[str]) -> List[str]:
    return path.split(os.pathsep) if path else []


def invalid_url(url: Optional[str]) -> Optional[str]:
    """Why ``url`` is no master URL, or None (an empty one is another rule's)."""
    if not url:
        return None
    p = urlparse(url)
    if p.scheme != "http":
        return "protocol is not 'http'"
    if not p.netloc:
        return "address is missing"
    if ":" not in p.netloc:
        return "port number is missing"
    parts = p.netloc.split(":")
    if len(parts) != 2:
        return f"invalid address string [{p.netloc}]"
    try:
        int(parts[1])
    except ValueError:
        return f"port number [{parts[1]}] is invalid"
    return None


def _writable_dir_check(path: Optional[str], name: str) -> Optional[str]:
    if path is None:
        return None
    if isfile(path):
        return f"{name} [{path}] must point to a directory, not a file"
    if not os.access(path, os.W_OK):
        return f"{name} [{path}] is not writable"
    return None


def ros_master_uri_hostname(ctx: WtfContext) -> Optional[str]:
    netloc = urlparse(ctx.ros_master_uri or "").netloc
    if netloc.count(":") != 1:
        return None  # another rule's
    host = netloc.split(":")[0]
    try:
        socket.getaddrinfo(host, 0, 0, 0, socket.SOL_TCP)
    except socket.gaierror:
        return f"Unknown host {host}"
    return None


environment_warnings: List[Rule] = [
    (lambda ctx: ctx.ros_package_path is None,
     "ROS_PACKAGE_PATH is not set. This is not required, but is unusual"),
    (lambda ctx: ctx.ros_package_path is not None and len(paths(ctx.ros_package_path)) == 0,
     "ROS_PACKAGE_PATH is empty. This is not required, but is unusual"),
    (lambda ctx: not ctx.ros_master_uri,
     "ROS_MASTER_URI is empty. This is not required, but is unusual"),
    (ros_master_uri_hostname, "Cannot resolve hostname in ROS_MASTER_URI [%(ros_master_uri)s]"),
    (lambda ctx: "ROSCONSOLE_CONFIG_FILE" in ctx.env and not isfile(ctx.env["ROSCONSOLE_CONFIG_FILE"]),
     "ROS_CONSOLE_CONFIG_FILE does not point to an existing file"),
]

environment_errors: List[Rule] = [
    (lambda ctx: ctx.ros_root is not None and not isdir(ctx.ros_root),
     "ROS_ROOT [%(ros_root)s] does not point to a directory"),
    (lambda ctx: [d for d in paths(ctx.ros_package_path) if d and isfile(d)],
     "Path(s) in ROS_PACKAGE_PATH [%(ros_package_path)s] points to a file instead of a directory: "),
    (lambda ctx: [d for d in paths(ctx.ros_package_path) if d and not isdir(d)],
     "Not all paths in ROS_PACKAGE_PATH [%(ros_package_path)s] point to an existing directory: "),
    (lambda ctx: [d for d in paths(ctx.pythonpath) if d and not isdir(d)],
     "Not all paths in PYTHONPATH [%(pythonpath)s] point to a directory: "),
    (lambda ctx: _writable_dir_check(ctx.env.get("ROS_HOME"), "ROS_HOME"), "ROS_HOME is invalid: "),
    (lambda ctx: _writable_dir_check(ctx.env.get("ROS_LOG_DIR"), "ROS_LOG_DIR"),
     "ROS_LOG_DIR is invalid: "),
    (lambda ctx: _writable_dir_check(ctx.env.get("ROS_TEST_RESULTS_DIR"), "ROS_TEST_RESULTS_DIR"),
     "ROS_TEST_RESULTS_DIR is invalid: "),
    (lambda ctx: invalid_url(ctx.ros_master_uri),
     "ROS_MASTER_URI [%(ros_master_uri)s] is not a valid URL: "),
]


def wtf_check_environment(ctx: WtfContext) -> None:
    for rule in environment_warnings:
        warning_rule(rule, rule[0](ctx), ctx)
    for rule in environment_errors:
        error_rule(rule, rule[0](ctx), ctx)


def _resolve(host: str) -> List[str]:
    family = socket.AF_INET6 if rosenv.use_ipv6() else socket.AF_INET
    return [info[4][0] for info in socket.getaddrinfo(host, 0, family, 0, socket.SOL_TCP)]


def ip_check(ctx: WtfContext) -> Optional[str]:
    """The host name must resolve to this host's addresses."""
    local = rosenv.get_local_addresses()
    try:
        resolved = _resolve(socket.gethostname())
    except socket.gaierror:
        return f"Local hostname [{socket.gethostname()}] cannot be resolved to an IP address"
    remote = sorted({ip for ip in resolved if not ip.startswith("127.") and ip != "::1"} - set(local))
    if remote:
        text = (f"Local hostname [{socket.gethostname()}] resolves to [{','.join(remote)}], which "
                f"does not appear to be a local IP address {local}.")
        return text.replace("%", "%%")
    return None


def ros_hostname_check(ctx: WtfContext) -> Optional[str]:
    hostname = ctx.env.get("ROS_HOSTNAME")
    if hostname is None:
        return None
    try:
        resolved = [info[4][0] for info in socket.getaddrinfo(hostname, 0, 0, 0, socket.SOL_TCP)]
    except socket.gaierror:
        return f"ROS_HOSTNAME [{hostname}] cannot be resolved to an IP address"
    local = rosenv.get_local_addresses()
    remote = sorted(set(resolved) - set(local))
    if remote:
        return (f"ROS_HOSTNAME [{hostname}] resolves to [{','.join(remote)}], which does not "
                f"appear to be a local IP address {local}.")
    return None


def ros_ip_check(ctx: WtfContext) -> Optional[str]:
    ip = ctx.env.get("ROS_IP")
    if ip is None:
        return None
    if " " in ip:
        return f"ROS_IP [{ip}] contains whitespace. This is not a valid IP."
    local = rosenv.get_local_addresses()
    if ip not in local:
        return (f"ROS_IP [{ip}] does not appear to be an IP address of a local network interface "
                f"(one of {local}).")
    return None


network_warnings: List[Rule] = [(ros_hostname_check, "ROS_HOSTNAME may be incorrect: "),
                                (ros_ip_check, "ROS_IP may be incorrect: ")]
network_errors: List[Rule] = [(ip_check, "Local network configuration is invalid: ")]


def wtf_check_network(ctx: WtfContext) -> None:
    for rule in network_warnings:
        warning_rule(rule, rule[0](ctx), ctx)
    for rule in network_errors:
        error_rule(rule, rule[0](ctx), ctx)


# ---------------------------------------------------------------------------------------------
# launch files (roswtf.roslaunchwtf's static checks)

def roslaunch_duplicate_node_check(ctx: WtfContext) -> List[str]:
    seen, dup = set(), []
    for config in ctx.launch_configs:
        for node in config.nodes:
            name = node.resolved_name
            if name in seen and name not in dup:
                dup.append(name)
            seen.add(name)
    return dup


def roslaunch_missing_pkgs_check(ctx: WtfContext) -> List[str]:
    return [p for p in ctx.launch_file_pkgs if packages.find_package(p) is None]


roslaunch_errors: List[Rule] = [
    (roslaunch_duplicate_node_check, "Multiple nodes of same name in packages:"),
    (roslaunch_missing_pkgs_check,
     "Cannot find the following required packages referenced in launch files:"),
]


def wtf_check_roslaunch_static(ctx: WtfContext) -> None:
    for rule in roslaunch_errors:
        error_rule(rule, rule[0](ctx), ctx)


# ---------------------------------------------------------------------------------------------
# the graph (roswtf.graph)

NODE_TIMEOUT = 3.0  # seconds for one node's answer


def _businfo(ctx: WtfContext, node: str, bus_info: List[Any]) -> List[Tuple[str, str, str]]:
    """``(topic, publisher, subscriber)`` of a node's live connections."""
    edges = []
    for info in bus_info:
        if len(info) < 5:
            continue
        dest = info[1]
        if isinstance(dest, str) and dest.startswith("http://"):
            dest = ctx.uri_node_map.get(dest, f"unknown ({dest})")
        connected = info[5] if len(info) > 5 else True
        if not connected:
            continue
        if info[2] == "i":
            edges.append((info[4], dest, node))
        elif info[2] == "o":
            edges.append((info[4], node, dest))
    return edges


def unexpected_edges(ctx: WtfContext) -> Optional[List[str]]:
    if not ctx.system_state or not ctx.nodes:
        return None
    return [f"{p}->{s} ({t})" for t, p, s in sorted(set(ctx.actual_edges) - set(ctx.expected_edges))]


def missing_edges(ctx: WtfContext) -> Optional[List[str]]:
    if not ctx.system_state or not ctx.nodes:
        return None
    return [f"{p}->{s} ({t})" for t, p, s in sorted(set(ctx.expected_edges) - set(ctx.actual_edges))]


def ping_check(ctx: WtfContext) -> Optional[List[str]]:
    if not ctx.system_state or not ctx.nodes:
        return None
    uris = {node: uri for uri, node in ctx.uri_node_map.items()}
    dead = []
    for node in sorted(ctx.nodes):
        try:
            with SlaveClient(uris[node], "/roswtf", NODE_TIMEOUT) as client:
                client.get_pid()
        except (KeyError, OSError):
            dead.append(node)
        except RemoteError:  # it answered: alive
            pass
    return dead


def simtime_check(ctx: WtfContext) -> Optional[bool]:
    if not ctx.use_sim_time:
        return None
    try:
        topics = Master("/roswtf").getPublishedTopics("/")
    except (MasterException, OSError):
        ctx.errors.append(WtfError("Cannot talk to ROS master"))
        raise WtfException(f"roswtf lost connection to the ROS Master at {ctx.ros_master_uri}") from None
    return None if any(t in ("/time", "/clock") for t, _ in topics) else True


def probe_all_services(ctx: WtfContext) -> List[str]:
    from minros.cli.service import get_service_headers

    master = Master("/roswtf")
    errors = []
    for service in ctx.services:
        try:
            uri = master.lookupService(service)
        except (MasterException, OSError):
            ctx.errors.append(WtfError(f"cannot contact ROS Master at {ctx.ros_master_uri}"))
            raise WtfException(f"roswtf lost connection to the ROS Master at {ctx.ros_master_uri}") from None
        try:
            if not get_service_headers(service, uri):
                errors.append(f"service [{service}] did not return service headers")
        except Exception as exc:  # noqa: BLE001 - whatever went wrong is the finding
            errors.append(f"service [{service}] appears to be malfunctioning: {exc}")
    return errors


def unconnected_subscriptions(ctx: WtfContext) -> str:
    ignored = ["/reset_time"] if ctx.use_sim_time else ["/time", "/clock"]
    out = ""
    for sub, topics in sorted(ctx.unconnected_subscriptions.items()):
        topics = [t for t in topics if t not in ignored]
        if topics:
            out += f" * {sub}:\n" + "".join(f"   * {t}\n" for t in topics)
    return out


graph_warnings: List[Rule] = [
    (unconnected_subscriptions, "The following node subscriptions are unconnected:\n"),
    (unexpected_edges, "The following nodes are unexpectedly connected:"),
]
graph_errors: List[Rule] = [
    (simtime_check, "/use_sim_time is set but no publisher of /clock is present"),
    (ping_check, "Could not contact the following nodes:"),
    (missing_edges, "The following nodes should be connected but aren't:"),
    (probe_all_services, "Errors connecting to the following services:"),
]


def _compute_online_context(ctx: WtfContext) -> None:
    master = Master("/roswtf", timeout=NODE_TIMEOUT)
    try:
        ctx.use_sim_time = bool(master.getParam("/use_sim_time"))
    except (MasterException, OSError):
        ctx.use_sim_time = False
    try:
        pubs, subs, srvs = ctx.system_state = master.getSystemState()
    except (MasterException, OSError):
        return
    ctx.topics = [t for t, _ in pubs + subs]
    ctx.services = [s for s, _ in srvs]
    ctx.service_providers = [n for _, names in srvs for n in names]
    ctx.nodes = sorted({n for state in ctx.system_state for _, names in state for n in names})
    start = time.time()
    for node in ctx.nodes:
        try:
            ctx.uri_node_map[master.lookupNode(node)] = node
        except MasterException:
            continue  # gone since: ping_check reports it
        except OSError:
            ctx.errors.append(WtfError(f"cannot contact ROS Master at {ctx.ros_master_uri}"))
            raise WtfException(f"roswtf lost connection to the ROS Master at {ctx.ros_master_uri}") from None
    if ctx.nodes and (time.time() - start) / len(ctx.nodes) > 0.5:
        ctx.warnings.append(WtfWarning("Communication with master is very slow (>0.5s average)"))
    publishers = {t: names for t, names in pubs}
    for topic, names in subs:
        for sub in names:
            if topic in publishers:
                ctx.expected_edges += [(topic, pub, sub) for pub in publishers[topic]]
            else:
                ctx.unconnected_subscriptions.setdefault(sub, []).append(topic)
    uris = {node: uri for uri, node in ctx.uri_node_map.items()}
    lock = threading.Lock()

    def ask(node: str) -> None:
        uri = uris.get(node)
        if uri is None:
            with lock:
                ctx.errors.append(WtfError(f"Master does not have lookup information for node [{node}]"))
            return
        t0 = time.time()
        try:
            with SlaveClient(uri, "/roswtf", NODE_TIMEOUT) as client:
                bus_info, refused = client.get_bus_info(), False
        except OSError:
            return  # ping_check reports it
        except RemoteError:
            bus_info, refused = None, True
        with lock:
            if time.time() - t0 > 1.0:
                ctx.warnings.append(WtfWarning(f"Communication with node [{node}] is very slow"))
            if refused:
                ctx.warnings.append(WtfWarning(f"Node [{node}] would not return bus info"))
            elif not bus_info:
                if node not in ctx.service_providers:
                    ctx.warnings.append(WtfWarning(f"Node [{node}] is not connected to anything"))
            else:
                ctx.actual_edges += _businfo(ctx, node, bus_info)

    threads = [threading.Thread(target=ask, args=(n,), daemon=True) for n in ctx.nodes]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(NODE_TIMEOUT * 3)


def wtf_check_graph(ctx: WtfContext, names: Optional[List[str]] = None) -> None:
    try:
        Master("/roswtf", timeout=NODE_TIMEOUT).getPid()
    except (MasterException, OSError):
        warning_rule((lambda c: True, "Cannot communicate with master, ignoring online checks"), True, ctx)
        return
    print("analyzing graph...")
    _compute_online_context(ctx)
    print("... done analyzing graph")
    print("running graph rules...")
    for rule in graph_warnings:
        warning_rule(rule, rule[0](ctx), ctx)
    for rule in graph_errors:
        error_rule(rule, rule[0](ctx), ctx)
    print("... done running graph rules")


# ---------------------------------------------------------------------------------------------
# the command (roswtf's main)

def print_results(ctx: WtfContext, out: Any = None) -> None:
    out = out or sys.stdout
    if not ctx.warnings and not ctx.errors:
        print("No errors or warnings", file=out)
        return
    if ctx.warnings:
        print(f"Found {len(ctx.warnings)} warning(s).\nWarnings are things that may be just fine, "
              "but are sometimes at fault\n", file=out)
        for warning in ctx.warnings:
            print("\033[1mWARNING\033[0m", warning.msg, file=out)
        print("", file=out)
    if ctx.errors:
        print(f"Found {len(ctx.errors)} error(s).\n", file=out)
        for error in ctx.errors:
            print("\033[31m\033[1mERROR\033[0m", error.msg, file=out)


def parse_options(argv: Sequence[str], prog: str = "roswtf") -> Any:
    """roswtf's options, parsed as roswtf parses them: optparse, so ``-h`` prints roswtf's
    text (``Usage:``, ``Options:``) and an unknown option exits 2 with its error."""
    import optparse

    parser = optparse.OptionParser(
        prog=prog, usage="usage: %prog [launch file]",
        description="roswtf is a tool for verifying a ROS installation and running system. "
                    "Checks provided launchfile if provided, else current stack or package.")
    parser.add_option("--all", dest="all_packages", default=False, action="store_true",
                      help="run roswtf against all packages")
    parser.add_option("--no-plugins", dest="disable_plugins", default=False,
                      action="store_true", help="disable roswtf plugins")
    parser.add_option("--offline", dest="offline", default=False, action="store_true",
                      help="only run offline tests")
    options, args = parser.parse_args(list(argv))
    options.launch_files = args
    return options


def main(argv: Sequence[str], prog: str = "minros wtf") -> int:
    options = parse_options(argv, prog)
    try:
        if options.launch_files:
            ctx = WtfContext.from_roslaunch(options.launch_files)
        else:
            _pkg_dir, pkg = packages.get_dir_pkg(os.getcwd())
            if pkg:
                print("Package:", pkg)
                ctx = WtfContext.from_package(pkg)
            else:
                print("No package or stack in the current directory")
                ctx = WtfContext.from_env()
        wtf_check_environment(ctx)
        wtf_check_network(ctx)
        wtf_check_roslaunch_static(ctx)
    except WtfException as exc:
        print(str(exc), file=sys.stderr)
        return 1
    print("=" * 80)
    print("Static checks summary:\n")
    print_results(ctx)
    del ctx.warnings[:]
    del ctx.errors[:]
    print("=" * 80)
    if options.offline or not ctx.ros_master_uri or invalid_url(ctx.ros_master_uri) or \
            not _master_online(ctx.ros_master_uri):
        print(f"\nROS Master does not appear to be running.\nOnline graph checks will not be run.\n"
              f"ROS_MASTER_URI is [{ctx.ros_master_uri}]")
        return 0
    print("Beginning tests of your ROS graph. These may take a while...")
    try:
        wtf_check_graph(ctx)
        print("\nOnline checks summary:\n")
    except WtfException as exc:
        print(str(exc), file=sys.stderr)
        print("\nAborting checks, partial results summary:\n")
    print_results(ctx)
    return 0


def _master_online(uri: str) -> bool:
    try:
        Master("/roswtf", master_uri=uri, timeout=NODE_TIMEOUT).getPid()
        return True
    except (MasterException, OSError):
        return False


def roswtf_main() -> None:
    """roswtf's entry point."""
    sys.exit(main(sys.argv[1:], prog="roswtf"))
