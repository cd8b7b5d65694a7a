"""``minros node`` / ``rosnode``: list, info, ping, kill, machine and cleanup nodes.

Texts and exit statuses follow Debian's rosnode (ros_comm 1.15). Every XML-RPC call has a
timeout, so a dead node makes ``ping``/``info`` report a failure instead of hanging.
"""

from __future__ import annotations

import errno
import optparse
import re
import socket
import sys
import time
from typing import Any, Callable, Dict, List, Tuple
from urllib.parse import urlparse

from minros import names
from minros.tools.common import ToolError, dispatch, option_parser, resolve, run_tool
from minros.tools.master import TOOL_TIMEOUT, Master, MasterException
from minros.wire import rosapi
from minros.wire.slaveapi import SlaveClient

NAME = "rosnode"
ID = "/rosnode"
CONNECTION_PATTERN = re.compile(r"\w+ connection on port (\d+) to \[(.*) on socket (\d+)\]")
PING_TIMEOUT = 3.0
USAGE = """rosnode is a command-line tool for printing information about ROS Nodes.

Commands:
\trosnode ping\ttest connectivity to node
\trosnode list\tlist active nodes
\trosnode info\tprint information about node
\trosnode machine\tlist nodes running on a particular machine or list machines
\trosnode kill\tkill a running node
\trosnode cleanup\tpurge registration information of unreachable nodes

Type rosnode <command> -h for more detailed usage, e.g. 'rosnode ping -h'
"""


class _Graph:
    """One master connection plus a cache of node URIs (as rosnode's _caller_apis)."""

    def __init__(self) -> None:
        self.master = Master(ID)
        self.uris: Dict[str, str | None] = {}

    def node_uri(self, node: str, skip_cache: bool = False) -> str | None:
        if skip_cache:
            self.uris.pop(node, None)
        return self.master.lookup_node_cached(self.uris, node)


def get_node_names(master: Master, namespace: str | None = None) -> List[str]:
    state = master.system_state()
    nodes: List[str] = []
    g_ns = names.make_global_ns(namespace) if namespace else None
    for section in state:
        for _name, node_list in section:
            for node in node_list:
                if g_ns is None or node.startswith(g_ns) or node == namespace:
                    nodes.append(node)
    return sorted(set(nodes))


def _remote_error(exc: rosapi.RemoteError) -> ToolError:
    """A node's non-SUCCESS answer (or a malformed one) as the tool's one line."""
    return ToolError(f"remote call failed: {str(exc)[:200]}")


# ---------------------------------------------------------------------------------------------
# list

def _cmd_list(argv: List[str], prog: str) -> int:
    p = option_parser(prog, "")
    p.add_option("-u", dest="list_uri", action="store_true", default=False, help="list XML-RPC URIs")
    p.add_option("-a", "--all", dest="list_all", action="store_true", default=False,
                 help="list all information")
    options, args = p.parse_args(argv)
    if len(args) > 1:
        p.error("invalid args: you may only specify one namespace")
    # rosnode resolves the namespace as the caller 'rostopic' (relative to ROS_NAMESPACE)
    namespace = resolve("rostopic", args[0]) if args else None
    print(_list_text(_Graph(), namespace, options.list_uri, options.list_all))
    return 0


def _list_text(graph: _Graph, namespace: str | None = None, list_uri: bool = False,
               list_all: bool = False) -> str:
    nodes = get_node_names(graph.master, namespace)
    if list_all:
        return "\n".join(f"{graph.node_uri(n) or 'unknown address'} \t{n}" for n in nodes)
    if list_uri:
        return "\n".join(graph.node_uri(n) or "unknown address" for n in nodes)
    return "\n".join(nodes)


# ---------------------------------------------------------------------------------------------
# info

def info_description(master: Master, node: str) -> str:
    state = master.system_state()
    published = master.getPublishedTopics("/")

    def topic_type(topic: str) -> str:
        for name, type_ in published:
            if name == topic:
                return type_
        return "unknown type"

    pubs = sorted(t for t, nodes in state[0] if node in nodes)
    subs = sorted(t for t, nodes in state[1] if node in nodes)
    srvs = sorted(s for s, nodes in state[2] if node in nodes)
    out = f"Node [{node}]"
    if pubs:
        out += "\nPublications: \n" + "\n".join(f" * {t} [{topic_type(t)}]" for t in pubs) + "\n"
    else:
        out += "\nPublications: None\n"
    if subs:
        out += "\nSubscriptions: \n" + "\n".join(f" * {t} [{topic_type(t)}]" for t in subs) + "\n"
    else:
        out += "\nSubscriptions: None\n"
    if srvs:
        out += "\nServices: \n" + "\n".join(f" * {s}" for s in srvs) + "\n"
    else:
        out += "\nServices: None\n"
    return out


def _lookup_uri(graph: _Graph, state: tuple, topic: str, uri: str) -> str:
    for section in state[0:2]:
        for name, nodes in section:
            if name == topic:
                for node in nodes:
                    if (graph.node_uri(node) or f"unknown address {node}") == uri:
                        return f"{node} ({uri})"
    return uri


def connection_description(graph: _Graph, node_uri: str) -> str:
    state = graph.master.system_state()
    try:
        with SlaveClient(node_uri, ID, TOOL_TIMEOUT) as client:
            pid = client.get_pid()
            out = f"Pid: {pid}\n"
            businfo = client.get_bus_info()
    except OSError:
        raise ToolError(f"Communication with node[{node_uri}] failed!") from None
    except rosapi.RemoteError as exc:
        raise _remote_error(exc) from None
    if businfo:
        out += "Connections:\n"
        for info in businfo:
            dest_id, direction, transport, topic = info[1], info[2], info[3], info[4]
            connected = info[5] if len(info) > 5 else True
            if not connected:
                continue
            out += f" * topic: {topic}\n"
            out += f"    * to: {_lookup_uri(graph, state, topic, dest_id)}\n"
            out += {"i": "    * direction: inbound", "o": "    * direction: outbound"}.get(
                direction, "    * direction: unknown")
            if len(info) > 6:
                match = CONNECTION_PATTERN.match(str(info[6]))
                if match is not None:
                    out += " ({} - {}) [{}]".format(*match.groups())
            out += "\n"
            out += f"    * transport: {transport}\n"
    return out


def _cmd_info(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] node1 [node2...]")
    p.add_option("-q", "--quiet", dest="quiet", action="store_true", default=False,
                 help="Prints only basic information such as pubs/subs and does not contact nodes for more information")
    options, nodes = p.parse_args(argv)
    if not nodes:
        p.error("You must specify at least one node name")
    graph = _Graph()
    for node in nodes:
        node = resolve("rosnode", node)
        print("-" * 80)
        print(info_description(graph.master, node))
        uri = graph.node_uri(node)
        if not uri:
            sys.stdout.flush()
            print(f"cannot contact [{node}]: unknown node", file=sys.stderr)
            continue
        if not options.quiet:
            print(f"\ncontacting node {uri} ...")
            print(connection_description(graph, uri))
    return 0


# ---------------------------------------------------------------------------------------------
# ping

def ping(graph: _Graph, node: str, max_count: int | None = None, verbose: bool = False,
         skip_cache: bool = False) -> bool:
    uri = graph.node_uri(node, skip_cache=skip_cache)
    if not uri:
        sys.stdout.flush()
        print(f"cannot ping [{node}]: unknown node", file=sys.stderr)
        return False
    if verbose:
        print(f"pinging {node} with a timeout of {PING_TIMEOUT}s")
    count = 0
    total = 0.0
    try:
        while True:
            start = time.time()
            try:
                with SlaveClient(uri, ID, PING_TIMEOUT) as client:
                    client.get_pid()
            except rosapi.RemoteError as exc:
                raise _remote_error(exc) from None
            except socket.timeout:
                sys.stdout.flush()
                print(f"connection to [{node}] timed out", file=sys.stderr)
                return False
            except OSError as exc:
                sys.stdout.flush()
                if isinstance(exc, ConnectionRefusedError) or exc.errno == errno.ECONNREFUSED:
                    fresh = graph.node_uri(node, skip_cache=True)
                    if not fresh:
                        print(f"cannot ping [{node}]: unknown node", file=sys.stderr)
                        return False
                    if fresh != uri:
                        if verbose:
                            print(f"node url has changed from [{uri}] to [{fresh}], retrying to ping")
                        uri = fresh
                        continue
                    print(f"ERROR: connection refused to [{uri}]", file=sys.stderr)
                elif isinstance(exc, socket.gaierror) and exc.errno == socket.EAI_NONAME:
                    # only "no such name": rosnode says "failed" when DNS cannot be asked
                    print(f"ERROR: Unknown host [{urlparse(uri).hostname}] for node [{node}]",
                          file=sys.stderr)
                else:
                    print(f"connection to [{node}] failed", file=sys.stderr)
                return False
            duration = (time.time() - start) * 1000.0
            total += duration
            count += 1
            if verbose:
                print(f"xmlrpc reply from {uri}\ttime={duration:f}ms")
                sys.stdout.flush()
            if max_count and count >= max_count:
                break
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    if verbose and count > 1:
        print(f"ping average: {total / count:f}ms")
    return True


def ping_all(graph: _Graph, verbose: bool = False) -> Tuple[List[str], List[str]]:
    nodes = get_node_names(graph.master)
    if verbose:
        print("Will ping the following nodes: \n" + "".join(f" * {n}\n" for n in nodes))
    pinged, unpinged = [], []
    for node in nodes:
        (pinged if ping(graph, node, max_count=1, verbose=verbose) else unpinged).append(node)
    return pinged, unpinged


def _cmd_ping(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [options] <node>")
    p.add_option("--all", "-a", dest="ping_all", action="store_true", default=False, help="ping all nodes")
    p.add_option("-c", dest="ping_count", type="int", metavar="COUNT", default=None,
                 help="number of pings to send. Not available with --all")
    options, args = p.parse_args(argv)
    graph = _Graph()
    if options.ping_all:
        if args:
            p.error(f"Invalid arguments '{' '.join(args)}' used with --all")
        if options.ping_count:
            p.error("-c may not be used with --all")
        ping_all(graph, verbose=True)
        return 0
    if not args:
        _missing_ping_target(p, graph)
    if len(args) > 1:
        p.error("you may only specify one input node")
    node = resolve("rosnode", args[0])
    print(f"rosnode: node is [{node}]")
    ping(graph, node, max_count=options.ping_count, verbose=True)
    return 0


def _missing_ping_target(p: optparse.OptionParser, graph: _Graph) -> None:
    """``ping`` without a node: the usage error, listing the nodes when the master answers.

    Debian's rosnode then prints the usage error a second time (its parser's exit is caught
    by the fallback meant for an unreachable master); the texts are kept identical."""
    from minros.tools.master import MasterError, MasterFailure, MasterIOError

    try:
        nodes = get_node_names(graph.master)
    except (MasterIOError, MasterError, MasterFailure):
        p.error("Please enter a node to ping")
    p.print_usage(sys.stderr)
    sys.stderr.write(f"{p.get_prog_name()}: error: Please enter a node to ping. Available nodes are:\n"
                     + "\n".join(nodes) + "\n")
    p.error("Please enter a node to ping")


# ---------------------------------------------------------------------------------------------
# kill, machine, cleanup

def kill_nodes(graph: _Graph, nodes: List[str]) -> Tuple[List[str], List[str]]:
    success, fail = [], []
    calls = []
    for node in nodes:
        uri = graph.node_uri(node)
        if uri:
            calls.append((node, uri))
        else:
            fail.append(node)
    for node, uri in calls:
        try:
            with SlaveClient(uri, ID, TOOL_TIMEOUT) as client:
                client.shutdown("user request")
        except (OSError, rosapi.RemoteError):
            pass
        success.append(node)
    return success, fail


def _cmd_kill(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [node]...")
    p.add_option("-a", "--all", dest="kill_all", action="store_true", default=False, help="kill all nodes")
    options, nodes = p.parse_args(argv)
    graph = _Graph()
    if options.kill_all:
        if nodes:
            p.error("invalid arguments with kill all (-a) option")
        targets = get_node_names(graph.master)
    elif not nodes:
        node_list = get_node_names(graph.master)
        if not node_list:
            print("No nodes running", file=sys.stderr)
            return 0
        sys.stdout.write("\n".join(f"{i + 1}. {n}" for i, n in enumerate(node_list)))
        sys.stdout.write("\n\nPlease enter the number of the node you wish to kill.\n> ")
        sys.stdout.flush()
        while True:
            line = sys.stdin.readline()
            if not line:
                return 1
            try:
                selection = int(line.strip())
            except ValueError:
                print("ERROR: please enter a number (ctrl-C to cancel)")
                sys.stdout.flush()
                continue
            if 1 <= selection <= len(node_list):
                break
            print("ERROR: invalid selection. Please enter a number (ctrl-C to cancel)")
            sys.stdout.flush()
        targets = [node_list[selection - 1]]
    else:
        targets = [resolve(ID, n) for n in nodes]
        known = get_node_names(graph.master)
        unknown = [n for n in targets if n not in known]
        if unknown:
            # rosnode lists them on further lines; one line is enough to name the problem
            raise ToolError("Unknown node(s): " + ", ".join(unknown))
    if not targets:
        print("No nodes running", file=sys.stderr)
        return 0
    if len(targets) > 1:
        print("killing:\n" + "\n".join(f" * {n}" for n in targets))
    else:
        print(f"killing {targets[0]}")
    _success, fail = kill_nodes(graph, targets)
    if fail:
        sys.stdout.flush()
        print("ERROR: Failed to kill:\n" + "\n".join(f" * {n}" for n in fail), file=sys.stderr)
        return 1
    print("killed")
    return 0


def _cmd_machine(argv: List[str], prog: str) -> int:
    p = option_parser(prog, " [machine-name]")
    _, args = p.parse_args(argv)
    if len(args) > 1:
        p.error("please enter only one machine name")
    graph = _Graph()
    if not args:
        nodes = get_node_names(graph.master)
        machines: List[str] = []
        for node in nodes:
            uri = graph.node_uri(node)
            host = urlparse(uri).hostname if uri else None
            if host and host not in machines:
                machines.append(host)
        print("\n".join(sorted(machines)))
        return 0
    machine = args[0]
    # the name is resolved before the master is asked (as rosnode: a bad name is reported
    # even when no master runs)
    try:
        wanted = {info[4][0] for info in socket.getaddrinfo(machine, 0, 0, 0, socket.SOL_TCP)}
    except (OSError, UnicodeError):
        raise ToolError(f"cannot resolve machine name [{machine}] to address") from None
    nodes = get_node_names(graph.master)
    matches = []
    for node in nodes:
        uri = graph.node_uri(node)
        host = urlparse(uri).hostname if uri else None
        if host is None:
            continue
        if host == machine or host in wanted:
            matches.append(node)
            continue
        try:
            addresses = {info[4][0] for info in socket.getaddrinfo(host, 0, 0, 0, socket.SOL_TCP)}
        except OSError:
            continue
        if addresses & wanted:
            matches.append(node)
    print("\n".join(sorted(matches)))
    return 0


def cleanup_master(graph: _Graph, dead: List[str]) -> None:
    """Unregister everything the ``dead`` nodes registered (on their behalf)."""
    pubs, subs, srvs = graph.master.system_state()
    for node in dead:
        print("Unregistering", node)
        uri = graph.node_uri(node)
        if not uri:
            continue
        as_node = Master(node, graph.master.uri)
        for topic, nodes in pubs:
            if node in nodes:
                as_node.raw("unregisterPublisher", topic, uri)
        for topic, nodes in subs:
            if node in nodes:
                as_node.raw("unregisterSubscriber", topic, uri)
        for service, nodes in srvs:
            if node in nodes:
                try:
                    service_uri = graph.master.lookupService(service)
                except MasterException:
                    continue
                as_node.raw("unregisterService", service, service_uri)
        graph.uris.pop(node, None)


def _cmd_cleanup(argv: List[str], prog: str) -> int:
    p = option_parser(prog, "")
    p.parse_args(argv)
    graph = _Graph()
    _pinged, unpinged = ping_all(graph)
    if not unpinged:
        return 0
    print("Unable to contact the following nodes:")
    print("\n".join(f" * {n}" for n in unpinged))
    print("Warning: these might include alive and functioning nodes, e.g. in unstable networks.")
    print("Cleanup will purge all information about these nodes from the master.")
    print("Please type y or n to continue:")
    sys.stdout.flush()
    while True:
        line = sys.stdin.readline()
        if not line:
            print("aborting")
            return 0
        if line.strip() in ("y", "n"):
            break
    if line.strip() == "n":
        print("aborting")
        return 0
    cleanup_master(graph, unpinged)
    print("done")
    return 0


COMMANDS = {"list": _cmd_list, "info": _cmd_info, "ping": _cmd_ping, "kill": _cmd_kill,
            "machine": _cmd_machine, "cleanup": _cmd_cleanup}


def main(argv: List[str], prog: str = "rosnode") -> int:
    return run_tool(lambda: dispatch(argv, prog, COMMANDS, USAGE, usage_status=64))


# ---------------------------------------------------------------------------------------------
# the Python API of ROS's rosnode module (the stand-in re-exports it)


class ROSNodeException(Exception):
    """A rosnode call failed."""


class ROSNodeIOException(ROSNodeException):
    """The master could not be reached."""


def _library(fn: Callable[[], Any]) -> Any:
    from minros.tools.common import library_call

    return library_call(fn, ROSNodeException, ROSNodeIOException)


def rosnode_get_node_names(namespace: str | None = None) -> List[str]:
    return _library(lambda: get_node_names(Master(ID), namespace))


def rosnode_ping(node_name: str, max_count: int | None = None, verbose: bool = False) -> bool:
    """Ping ``node_name`` through its getPid; True when it answered."""
    return _library(lambda: ping(_Graph(), node_name, max_count, verbose))


def rosnode_ping_all(verbose: bool = False) -> Tuple[List[str], List[str]]:
    return _library(lambda: ping_all(_Graph(), verbose))


def rosnode_kill_nodes(node_names: List[str]) -> Tuple[List[str], List[str]]:
    """Ask each node to shut down: ``(killed, unknown)``."""
    return _library(lambda: kill_nodes(_Graph(), list(node_names)))


def rosnode_get_api_uri(master: Any, caller_id: str, skip_cache: bool = False) -> str | None:
    return _library(lambda: _Graph().node_uri(caller_id, skip_cache))


def rosnodemain(argv: List[str] | None = None) -> None:
    """The rosnode command (``argv`` as sys.argv, program name first)."""
    sys.exit(main(list(sys.argv if argv is None else argv)[1:]))


# -- more of rosnode's Python API: the pieces its commands print, and the clean-up helpers

def _graph_of(master: Any) -> _Graph:
    """A _Graph asking ``master`` (a rosgraph.Master) when it is minros's, else the
    environment's master."""
    graph = _Graph()
    if isinstance(master, Master):
        graph.master = master
    return graph


def rosnode_listnodes(namespace: str | None = None, list_uri: bool = False,
                      list_all: bool = False) -> None:
    """Print the nodes (under ``namespace``), their URIs (``list_uri``) or both."""
    print(_library(lambda: _list_text(_Graph(), namespace, list_uri, list_all)))


def lookup_uri(master: Any, system_state: Any, topic: str, uri: str) -> str:
    """``'node (uri)'`` for the node of ``topic`` whose API is ``uri``, else ``uri``."""
    return _library(lambda: _lookup_uri(_graph_of(master), system_state, topic, uri))


def get_node_info_description(node_name: str) -> str:
    """The publications, subscriptions and services ``rosnode info`` prints for a node."""
    return _library(lambda: info_description(Master(ID), node_name))


def get_node_connection_info_description(node_api: str, master: Any) -> str:
    """The pid and connections of the node at ``node_api``, asked of the node itself."""
    def run() -> str:
        try:
            return connection_description(_graph_of(master), node_api)
        except ToolError as exc:
            raise ROSNodeIOException(exc.text) from None

    return _library(run)


def rosnode_info_api(node_name: str, quiet: bool = False) -> None:
    """Print what ``rosnode info [-q] NODE`` prints."""
    def run() -> None:
        graph = _Graph()
        node = resolve(NAME, node_name)
        print("-" * 80)
        print(info_description(graph.master, node))
        uri = graph.node_uri(node)
        if not uri:
            sys.stdout.flush()
            print(f"cannot contact [{node}]: unknown node", file=sys.stderr)
            return
        if not quiet:
            print(f"\ncontacting node {uri} ...")
            print(connection_description(graph, uri))

    _library(run)


def _hosts_of(graph: _Graph) -> List[Tuple[str, str]]:
    """``(node, host)`` of every node the master can name a URI for."""
    out = []
    for node in get_node_names(graph.master):
        uri = graph.node_uri(node)
        host = urlparse(uri).hostname if uri else None
        if host:
            out.append((node, host))
    return out


def get_machines_by_nodes() -> List[str]:
    """The host names in the URIs of the running nodes (one master lookup per node)."""
    def run() -> List[str]:
        machines: List[str] = []
        for _node, host in _hosts_of(_Graph()):
            if host not in machines:
                machines.append(host)
        return machines

    return _library(run)


def get_nodes_by_machine(machine: str) -> List[str]:
    """The nodes whose URI's host is ``machine`` or resolves to one of its addresses."""
    def addresses(host: str) -> set:
        return {info[4][0] for info in socket.getaddrinfo(host, 0, 0, 0, socket.SOL_TCP)}

    try:
        wanted = addresses(machine)
    except (OSError, UnicodeError):
        raise ROSNodeException(f"cannot resolve machine name [{machine}] to address") from None

    def run() -> List[str]:
        found = []
        for node, host in _hosts_of(_Graph()):
            if host == machine or host in wanted:
                found.append(node)
                continue
            try:
                if addresses(host) & wanted:
                    found.append(node)
            except (OSError, UnicodeError):
                continue
        return found

    return _library(run)


def cleanup_master_blacklist(master: Any, blacklist: List[str]) -> None:
    """Unregister every topic and service the nodes of ``blacklist`` registered."""
    _library(lambda: cleanup_master(_graph_of(master), list(blacklist)))


def cleanup_master_whitelist(master: Any, whitelist: List[str]) -> None:
    """Unregister every registration of the nodes not in ``whitelist``."""
    def run() -> None:
        graph = _graph_of(master)
        pubs, subs, srvs = graph.master.system_state()
        for method, section in (("unregisterPublisher", pubs), ("unregisterSubscriber", subs)):
            for topic, nodes in section:
                for node in nodes:
                    if node not in whitelist:
                        Master(node, graph.master.uri).raw(method, topic, graph.node_uri(node) or "")
        for service, nodes in srvs:
            for node in nodes:
                if node not in whitelist:
                    try:
                        service_uri = graph.master.lookupService(service)
                    except MasterException:
                        continue
                    Master(node, graph.master.uri).raw("unregisterService", service, service_uri)

    _library(run)


def rosnode_cleanup() -> None:
    """``rosnode cleanup``: ping every node, then (asking y/n on stdin) purge the master's
    registrations of those that did not answer."""
    _library(lambda: _cmd_cleanup([], "rosnode cleanup"))


if __name__ == "__main__":  # rosrun rosnode rosnode
    sys.exit(main(sys.argv[1:]))
