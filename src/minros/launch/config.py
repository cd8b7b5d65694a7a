"""The launch model a .launch file loads into: parameters, nodes, setup commands, warnings."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Tuple

from minros import names


class LaunchError(Exception):
    """A launch file that cannot be loaded or run. ``str()`` is the one line the user sees:
    ``FILE:LINE: message`` when the place is known."""

    def __init__(self, message: str, filename: str | None = None, line: int | None = None) -> None:
        self.message = message
        self.filename = filename
        self.line = line
        super().__init__(self.__str__())

    def __str__(self) -> str:
        if self.filename and self.line:
            return f"{self.filename}:{self.line}: {self.message}"
        if self.filename:
            return f"{self.filename}: {self.message}"
        return self.message


@dataclass
class NodeSpec:
    """One ``<node>`` (or ``<test>``) after substitution."""

    package: str
    type: str
    name: str
    namespace: str = "/"
    args: str = ""
    remap_args: List[Tuple[str, str]] = field(default_factory=list)
    env_args: List[Tuple[str, str]] = field(default_factory=list)
    output: str | None = None  # 'log' (default) or 'screen'
    respawn: bool = False
    respawn_delay: float = 0.0
    required: bool = False
    cwd: str | None = None  # 'ROS_HOME' (default) or 'node'
    launch_prefix: str | None = None
    machine: str | None = None
    filename: str | None = None
    line: int | None = None
    test_name: str | None = None
    time_limit: float | None = None
    retry: int = 0  # a <test>'s reruns after a failure

    @property
    def resolved_name(self) -> str:
        return names.ns_join(self.namespace, self.name)


@dataclass
class Machine:
    name: str
    address: str
    default: str = "false"
    # how to reach it (roslaunch's <machine> attributes; minros launches locally only)
    env_loader: str | None = None
    user: str | None = None
    password: str | None = None
    ssh_port: int = 22
    timeout: float | None = None


@dataclass
class LaunchConfig:
    """Everything to do for a launch, in order: clear, setup commands, set params, start nodes."""

    params: Dict[str, Any] = field(default_factory=dict)
    clear_params: List[str] = field(default_factory=list)
    #: ('delete', key) / ('dump', file, key), run before parameters are set
    rosparam_commands: List[Tuple[str, ...]] = field(default_factory=list)
    nodes: List[NodeSpec] = field(default_factory=list)
    tests: List[NodeSpec] = field(default_factory=list)
    machines: Dict[str, Machine] = field(default_factory=dict)
    warnings: List[str] = field(default_factory=list)
    files: List[str] = field(default_factory=list)
    #: declared args of the top file: name -> (doc, default)
    arg_docs: Dict[str, Tuple[str | None, str | None]] = field(default_factory=dict)

    def add_param(self, key: str, value: Any) -> None:
        for parent in _parents(key):
            if parent in self.params:
                self.warnings.append(f"parameter [{key}] conflicts with parent parameter [{parent}]")
        self.params[key] = value

    def add_clear_param(self, ns: str) -> None:
        if ns not in self.clear_params:
            self.clear_params.append(ns)

    def add_node(self, node: NodeSpec) -> None:
        name = node.resolved_name
        if any(n.resolved_name == name for n in self.nodes):
            raise LaunchError(
                f"roslaunch file contains multiple nodes named [{name}]. Please check all <node> 'name' "
                "attributes to make sure they are unique. Also check that $(anon id) use different ids.",
                node.filename, node.line)
        self.nodes.append(node)

    def summary(self) -> str:
        """The SUMMARY block roslaunch prints before starting anything."""
        out = ["", "SUMMARY", "========"]
        if self.clear_params:
            out += ["", "CLEAR PARAMETERS"] + sorted(f" * {p}" for p in self.clear_params)
        if self.params:
            out += ["", "PARAMETERS"] + sorted(f" * {k}: {_short(v)}" for k, v in self.params.items())
        out += ["", "NODES"]
        by_ns: Dict[str, List[NodeSpec]] = {}
        for node in self.nodes:
            by_ns.setdefault(node.namespace, []).append(node)
        for ns in sorted(by_ns):
            out.append(f"  {ns}")
            out += sorted(f"    {n.name} ({n.package}/{n.type})" for n in by_ns[ns])
        return "\n".join(out) + "\n"


def _parents(key: str) -> List[str]:
    parts = [p for p in key.split("/") if p]
    return ["/" + "/".join(parts[:i]) for i in range(1, len(parts))]


def _short(value: Any) -> str:
    """A parameter value as the summary shows it: at most 20 characters, printable only."""
    text = str(value)  # a Binary shows its bytes decoded as latin-1, as in roslaunch
    if len(text) > 20:
        text = text[:17] + "..."
    def printable(s: str) -> bool:
        return all(32 <= ord(c) <= 126 for c in s)

    if printable(text):
        return text
    text = text.rstrip()  # trailing newlines ("Debian\n") are fine, anything else is not
    return text if printable(text) else "<...>"
