"""roslaunch's scripting API: ROSLaunchParent (launch files from Python), scriptapi.ROSLaunch
(start single nodes), core.Node, and rlutil's run id, over the same loader and runner as the
``roslaunch`` command."""

from __future__ import annotations

import os
import re
import threading
import uuid
from typing import Any, Dict, List, Sequence, Tuple

from minros import names
from minros.launch.config import LaunchConfig, LaunchError, NodeSpec
from minros.launch.loader import Loader
from minros.launch.runner import LaunchProcess, LaunchRunner, master_is_up
from minros.rosenv import get_master_uri

__all__ = ["Node", "ROSLaunchParent", "ROSLaunch", "get_or_generate_uuid", "RLException"]

#: roslaunch's exception name for what minros calls LaunchError
RLException = LaunchError


def _namespace(ns: str | None) -> str:
    return re.sub("//+", "/", names.make_global_ns(ns or "/"))


def _cwd(cwd: str | None) -> str | None:
    return "ROS_HOME" if cwd == "ros_home" else cwd  # lenient on case, as roslaunch


def validate_node(node: NodeSpec) -> None:
    """roslaunch's checks of a node's settings, with its texts (ValueError)."""
    if node.respawn and node.required:
        raise ValueError("respawn and required cannot both be set to true")
    if node.name and "/" in node.name:
        raise ValueError("node name cannot contain a namespace")
    if not node.package.strip():
        raise ValueError("package must be non-empty")
    if not node.type.strip():
        raise ValueError("type must be non-empty")
    if node.output not in ("log", "screen", None):
        raise ValueError("output must be one of 'log', 'screen'")
    if node.cwd not in ("ROS_HOME", "node", None):
        raise ValueError("cwd must be one of 'ROS_HOME', 'node'")


class Node(NodeSpec):
    """roslaunch.core.Node: a node to launch, with roslaunch's constructor."""

    def __init__(self, package: str, node_type: str, name: str | None = None,
                 namespace: str = "/", machine_name: str | None = None, args: str = "",
                 respawn: bool = False, respawn_delay: float = 0.0,
                 remap_args: Sequence[Tuple[str, str]] | None = None,
                 env_args: Sequence[Tuple[str, str]] | None = None, output: str | None = None,
                 cwd: str | None = None, launch_prefix: str | None = None, required: bool = False,
                 filename: str = "<unknown>") -> None:
        super().__init__(package=package, type=node_type, name=name or "",
                         namespace=_namespace(namespace), args=args or "",
                         remap_args=list(remap_args or []), env_args=list(env_args or []),
                         output=output, respawn=respawn, respawn_delay=respawn_delay,
                         required=required, cwd=_cwd(cwd), launch_prefix=launch_prefix or None,
                         machine=None, filename=filename)
        #: the <machine> named in the launch file; ``machine`` is that Machine once assigned
        self.machine_name = machine_name or None
        validate_node(self)

    @property
    def node_type(self) -> str:
        return self.type

    def xmltype(self) -> str:
        return "node"

    def xmlattrs(self) -> List[Tuple[str, Any]]:
        return node_xmlattrs(self)

    def to_xml(self) -> str:
        """The node as launch XML (private parameters are not part of it)."""
        return node_to_xml(self)

    def to_remote_xml(self) -> str:
        return node_to_xml(self, remote=True)


def _xml_escape(s: Any) -> Any:
    """``s`` with ``< > & "`` escaped (other values as they are)."""
    if isinstance(s, str):
        from xml.sax.saxutils import escape

        return escape(s, entities={'"': "&quot;"})
    return s


def node_xmlattrs(node: Any) -> List[Tuple[str, Any]]:
    """The attributes of a node's XML element, as roslaunch writes them."""
    return [("pkg", node.package), ("type", node.type), ("machine", getattr(node, "machine_name", None)),
            ("ns", node.namespace), ("args", node.args), ("output", node.output),
            ("cwd", node.cwd or None), ("respawn", node.respawn),
            ("respawn_delay", node.respawn_delay), ("name", node.name or None),
            ("launch-prefix", node.launch_prefix), ("required", node.required)]


def node_to_xml(node: Any, remote: bool = False) -> str:
    """A node as launch XML (its remappings and environment included)."""
    tag = node.xmltype()
    attrs = [(a, v) for a, v in node.xmlattrs() if v is not None and not (remote and a == "machine")]
    out = f"<{tag} " + " ".join(f'{a}="{_xml_escape(v)}"' for a, v in attrs) + ">\n"
    out += "".join(f'  <remap from="{a}" to="{b}" />\n' for a, b in node.remap_args)
    out += "".join(f'  <env name="{a}" value="{b}" />\n' for a, b in node.env_args)
    return out + f"</{tag}>"


def get_or_generate_uuid(options_runid: str | None = None,
                         options_wait_for_master: bool = False) -> str:
    """The run id: the one given, else the master's /run_id, else a new uuid1."""
    if options_runid:
        return options_runid
    uri = get_master_uri()
    if master_is_up(uri):
        from minros.tools.master import Master

        master = Master("/roslaunch", uri)
        try:
            value = master.get_param("/run_id")
        except Exception:  # unset, or the master went away: a new one
            value = None
        finally:
            master.close()
        if value:
            return str(value)
    return str(uuid.uuid1())


class ROSLaunchParent:
    """Launch files (or launch XML strings) from Python: ``start()``, ``spin()``/``spin_once()``,
    ``shutdown()``, as roslaunch.parent.ROSLaunchParent."""

    def __init__(self, run_id: str, roslaunch_files: Sequence[Any], is_core: bool = False,
                 port: int | None = None, local_only: bool = False, process_listeners: Any = None,
                 verbose: bool = False, force_screen: bool = False, force_log: bool = False,
                 is_rostest: bool = False, roslaunch_strs: Sequence[str] | None = None,
                 num_workers: int = 1, timeout: float | None = None,
                 master_logger_level: Any = False, show_summary: bool = True,
                 sigint_timeout: float = 15.0, sigterm_timeout: float = 2.0) -> None:
        self.run_id = run_id
        self.roslaunch_files = list(roslaunch_files)
        self.roslaunch_strs = list(roslaunch_strs or [])
        self.is_core = is_core
        self.port = port
        self.force_screen = force_screen
        self.sigint_timeout = sigint_timeout
        self.sigterm_timeout = sigterm_timeout
        self.process_listeners = list(process_listeners or [])
        self.runner: LaunchRunner | None = None
        self._monitor: threading.Thread | None = None

    def _config(self) -> LaunchConfig:
        loader = Loader()
        for entry in self.roslaunch_files:
            # an entry may be (file, [arg:=value...]) as in ROS
            path, args = (entry[0], list(entry[1])) if isinstance(entry, (tuple, list)) else (entry, [])
            loader.load(str(path), args)
        for index, text in enumerate(self.roslaunch_strs):
            loader.load_string(text, [], f"<string {index}>")
        return loader.config

    def start(self, auto_terminate: bool = True) -> None:
        """Load the files, start the master when none runs, set the parameters, start nodes."""
        uri = get_master_uri()
        if self.port:
            uri = f"http://localhost:{self.port}/"
        self.runner = LaunchRunner(self._config(), master_uri=uri, port=self.port,
                                   screen=self.force_screen, run_id=self.run_id,
                                   core_only=self.is_core, sigint_timeout=self.sigint_timeout,
                                   sigterm_timeout=self.sigterm_timeout)
        self.runner.start()
        self._monitor = threading.Thread(target=self.runner.monitor, daemon=True,
                                         name="roslaunch-monitor")
        self._monitor.start()

    def spin_once(self) -> None:
        if self.runner is not None:
            self.runner.shutdown.wait(0.1)

    def spin(self) -> None:
        """Block until the launch ends (a required node died, every node exited, shutdown)."""
        if self.runner is None:
            raise RLException("parent not started yet")
        while not self.runner.shutdown.wait(0.1):
            pass
        self.shutdown()

    def shutdown(self) -> None:
        """Stop every node (and the master this launch started)."""
        if self.runner is not None:
            self.runner.stop()
            if self._monitor is not None:
                self._monitor.join(timeout=10)


class LaunchedProcess:
    """What scriptapi.ROSLaunch.launch returns: a running node."""

    def __init__(self, process: LaunchProcess) -> None:
        self._process = process
        self.name = process.name

    def is_alive(self) -> bool:
        return self._process.poll()

    @property
    def exit_code(self) -> int | None:
        self._process.poll()
        return self._process.exit_code

    def get_exit_code(self) -> int | None:
        return self.exit_code

    def stop(self) -> None:
        self._process.stop(15.0, 2.0, lambda _text: None)

    @property
    def pid(self) -> int | None:
        popen = self._process.popen
        return popen.pid if popen is not None else None


class ROSLaunch:
    """roslaunch.scriptapi.ROSLaunch: start nodes one by one from Python."""

    def __init__(self) -> None:
        self.parent: ROSLaunchParent | None = None
        self._processes: List[LaunchedProcess] = []
        self._counter = 0

    def load(self, f: str) -> None:
        raise NotImplementedError("use ROSLaunchParent to run launch files")

    def start(self, auto_terminate: bool = True) -> None:
        self.parent = ROSLaunchParent(get_or_generate_uuid(), [])
        self.parent.start(auto_terminate)

    def launch(self, node: NodeSpec) -> LaunchedProcess:
        """Start ``node``; returns the running process (``is_alive()``, ``stop()``)."""
        if self.parent is None or self.parent.runner is None:
            raise RLException("ROSLaunch has not been started")
        runner = self.parent.runner
        if not node.name:
            node.name = names.anonymous_name(node.type.replace(".", "_"))
        self._counter += 1
        proc_name = f"{names.ns_join(node.namespace, node.name).lstrip('/')}-{self._counter}"
        argv, cwd = runner.node_command(node, proc_name)
        env: Dict[str, str] = runner.node_env(node)
        os.makedirs(cwd, exist_ok=True)
        process = LaunchProcess(proc_name, argv, env, cwd, spec=node, log_dir=runner.log_dir,
                                screen=runner.screen or node.output == "screen")
        try:
            process.start()
        except OSError as exc:
            raise RLException(f"failed to start {node.package}/{node.type}: {exc.strerror}") from None
        launched = LaunchedProcess(process)
        self._processes.append(launched)
        return launched

    def spin(self) -> None:
        if self.parent is not None:
            self.parent.spin()

    def stop(self) -> None:
        for process in self._processes:
            process.stop()
        self._processes = []
        if self.parent is not None:
            self.parent.shutdown()
